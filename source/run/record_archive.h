#ifndef hysteron_source_run_record_archive_h
#define hysteron_source_run_record_archive_h

// Keyed checkpoint records (run/keyed_records.h) described once for save and load.
#include <hysteron/base/checkpoint.h>

#include "run/keyed_records.h"

#include <sstream>

namespace hysteron
{
  namespace Run
  {
    /**
     * Write one record per key of @p keys into @p path: @p describe(archive, k) is the
     * one description of the k-th record, the same function load_records() reads it
     * back with (a generic lambda over the archive, as a serialize() is).
     * Collective.
     */
    template <typename Describe>
    void
    save_records(const std::string                &path,
                 const std::uint64_t               n_keys,
                 const std::vector<std::uint64_t> &keys,
                 MPI_Comm                          comm,
                 const Describe                   &describe)
    {
      std::vector<std::pair<std::uint64_t, std::string>> records;
      records.reserve(keys.size());
      for (std::size_t k = 0; k < keys.size(); ++k)
        {
          std::ostringstream bytes;
          CheckpointWriter   out(bytes);
          describe(out, k);
          records.emplace_back(keys[k], bytes.str());
        }
      write_records(path, n_keys, records, comm);
    }

    /**
     * Read back what save_records() wrote for @p keys with the same @p describe; a
     * record longer than its description is refused (another mesh or network).
     * Refusals reach every rank (parse_collectively). Collective.
     */
    template <typename Describe>
    void
    load_records(const std::string &path, const std::vector<std::uint64_t> &keys, MPI_Comm comm, const Describe &describe)
    {
      const auto records = read_records(path, keys, comm);
      parse_collectively(comm, [&]() {
        for (std::size_t k = 0; k < keys.size(); ++k)
          {
            std::istringstream bytes(records[k]);
            CheckpointReader   in(bytes, path);
            describe(in, k);
            if (!in.at_end())
              in.refuse("a record is longer than its description here (another mesh, network or material)");
          }
      });
    }
  } // namespace Run
} // namespace hysteron

#endif
