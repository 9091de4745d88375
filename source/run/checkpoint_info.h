// The description of a checkpoint on disk, shared by its writer and its reader: the
// directory names, info.txt and the CRC-32 digests it lists.
#ifndef hysteron_source_run_checkpoint_info_h
#define hysteron_source_run_checkpoint_info_h

#include "run/checkpoint_files.h"

#include <cstdint>
#include <filesystem>
#include <string>

namespace hysteron
{
  namespace Run
  {
    namespace CheckpointInfo
    {
      /// "checkpoint-<step>" (nine digits at least): the name of the checkpoint of @p step.
      std::string
      name(unsigned long step);

      /// The step of a directory named checkpoint-<digits>, or -1.
      long
      step_of(const std::string &name);

      /// @p crc as eight hexadecimal digits.
      std::string
      hex(std::uint32_t crc);

      /// The digest of the first @p bytes of @p path (rank 0 reads it all; small files).
      FileDigest
      digest(const std::string &path, std::uint64_t bytes);

      /**
       * The text of info.txt for @p file: the format's magic line, step, time
       * (hexadecimal: exact), ranks, then "<kind> <bytes> <crc> <path>" per file,
       * table and input, and last "end <CRC-32 of the text before it>".
       */
      std::string
      text(const CheckpointFile &file);

      /// Read info.txt of @p directory into @p file; false and the reason in @p why if
      /// it is missing, damaged or of another version.
      bool
      read(const std::filesystem::path &directory, CheckpointFile &file, std::string &why);
    } // namespace CheckpointInfo
  } // namespace Run
} // namespace hysteron

#endif
