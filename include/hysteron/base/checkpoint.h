#ifndef hysteron_base_checkpoint_h
#define hysteron_base_checkpoint_h

#include <array>
#include <cstdint>
#include <cstring>
#include <istream>
#include <map>
#include <ostream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace hysteron
{
  namespace internal
  {
    /// Does T have a member template serialize(Archive &)?
    template <typename T, typename Archive, typename = void>
    struct has_serialize : std::false_type
    {};

    template <typename T, typename Archive>
    struct has_serialize<T, Archive, std::void_t<decltype(std::declval<T &>().serialize(std::declval<Archive &>()))>>
      : std::true_type
    {};
  } // namespace internal

  /// How a section starts in the file: "section:<name> v<version>".
  inline std::string
  section_tag(const std::string &name, const std::uint32_t version)
  {
    return "section:" + name + " v" + std::to_string(version);
  }



  /**
   * The binary archive a checkpoint is written with. As in Boost and deal.II,
   * a state describes itself once, in
   * @code
   *   template <class Archive> void serialize(Archive &ar)
   *   { ar.section("my state", 1); ar & a & b & c; }
   * @endcode
   * and the same function writes it (with a CheckpointWriter) and reads it
   * back (with a CheckpointReader), so that a field saved but not restored
   * cannot happen. `Archive::is_loading` tells the two apart where loading
   * needs a check or a rebuild. Values are stored bit for bit (trivially
   * copyable types: double, integers, deal.II's Point, Tensor and
   * SymmetricTensor; strings, vectors, arrays, pairs, maps of them; classes
   * with a serialize() member), so that a resumed run continues from exactly
   * the state of the interrupted one. Named sections make the reader refuse a
   * checkpoint of another method instead of misreading it, and each section
   * carries the version of its format: a serialize() that changes what it
   * stores raises its version, so that an older checkpoint is refused with
   * both versions named rather than read wrongly.
   */
  class CheckpointWriter
  {
  public:
    static constexpr bool is_loading = false;

    explicit CheckpointWriter(std::ostream &out)
      : out(out)
    {}

    /// Start a section in format @p version: the reader must ask for the same name and version here.
    void
    section(const std::string &name, const std::uint32_t version)
    {
      put(section_tag(name, version));
    }

    template <typename T>
    CheckpointWriter &
    operator&(const T &value)
    {
      put(value);
      return *this;
    }

    template <typename T>
    void
    put(const T &value)
    {
      if constexpr (internal::has_serialize<T, CheckpointWriter>::value)
        const_cast<T &>(value).serialize(*this); // serialize() only reads when writing
      else
        {
          static_assert(std::is_trivially_copyable_v<T>, "only trivially copyable values");
          out.write(reinterpret_cast<const char *>(&value), sizeof(T));
        }
    }

    void
    put(const std::string &value)
    {
      put<std::uint64_t>(value.size());
      out.write(value.data(), value.size());
    }

    template <typename T>
    void
    put(const std::vector<T> &values)
    {
      put<std::uint64_t>(values.size());
      if constexpr (std::is_trivially_copyable_v<T> && !internal::has_serialize<T, CheckpointWriter>::value)
        out.write(reinterpret_cast<const char *>(values.data()), sizeof(T) * values.size());
      else
        for (const auto &v : values)
          put(v);
    }

    void
    put(const std::vector<bool> &values)
    {
      put<std::uint64_t>(values.size());
      for (const bool v : values)
        put<char>(v);
    }

    template <typename T, std::size_t N>
    void
    put(const std::array<T, N> &values)
    {
      for (const auto &v : values)
        put(v);
    }

    template <typename A, typename B>
    void
    put(const std::pair<A, B> &value)
    {
      put(value.first);
      put(value.second);
    }

    template <typename K, typename V>
    void
    put(const std::map<K, V> &values)
    {
      put<std::uint64_t>(values.size());
      for (const auto &v : values)
        put(v);
    }

  private:
    std::ostream &out;
  };

  /// Reads what CheckpointWriter wrote; every mismatch is an InputError naming the file.
  class CheckpointReader
  {
  public:
    static constexpr bool is_loading = true;

    CheckpointReader(std::istream &in, const std::string &filename)
      : in(in)
      , filename(filename)
    {}

    /// Check that the next section is @p name in format @p version.
    void
    section(const std::string &name, std::uint32_t version);

    template <typename T>
    CheckpointReader &
    operator&(T &value)
    {
      get(value);
      return *this;
    }

    template <typename T>
    void
    get(T &value)
    {
      if constexpr (internal::has_serialize<T, CheckpointReader>::value)
        value.serialize(*this);
      else
        {
          static_assert(std::is_trivially_copyable_v<T>, "only trivially copyable values");
          read(reinterpret_cast<char *>(&value), sizeof(T));
        }
    }

    template <typename T>
    T
    get()
    {
      T value;
      get(value);
      return value;
    }

    void
    get(std::string &value)
    {
      value.resize(get_size());
      read(value.data(), value.size());
    }

    template <typename T>
    void
    get(std::vector<T> &values)
    {
      values.resize(get_size());
      if constexpr (std::is_trivially_copyable_v<T> && !internal::has_serialize<T, CheckpointReader>::value)
        read(reinterpret_cast<char *>(values.data()), sizeof(T) * values.size());
      else
        for (auto &v : values)
          get(v);
    }

    void
    get(std::vector<bool> &values)
    {
      values.resize(get_size());
      for (std::size_t i = 0; i < values.size(); ++i)
        values[i] = get<char>() != 0;
    }

    template <typename T, std::size_t N>
    void
    get(std::array<T, N> &values)
    {
      for (auto &v : values)
        get(v);
    }

    template <typename A, typename B>
    void
    get(std::pair<A, B> &value)
    {
      get(value.first);
      get(value.second);
    }

    template <typename K, typename V>
    void
    get(std::map<K, V> &values)
    {
      values.clear();
      const std::size_t n = get_size();
      for (std::size_t i = 0; i < n; ++i)
        {
          std::pair<K, V> v;
          get(v);
          values.insert(v);
        }
    }

    /// Whether the whole stream has been read.
    bool
    at_end()
    {
      return in.peek() == std::char_traits<char>::eof();
    }

    /// Refuse the checkpoint: "<file>: <problem>".
    [[noreturn]] void
    refuse(const std::string &problem) const;

  private:
    std::size_t
    get_size();

    void
    read(char *data, std::size_t n);

    std::istream &in;
    std::string   filename;
  };



  /// A file as the run read it (an input) or wrote it (a checkpoint's file, a table
  /// at a checkpoint): its path, its first @p bytes and their CRC-32.
  struct FileDigest
  {
    std::string   path;
    std::uint64_t bytes = 0;
    std::uint32_t crc   = 0;

    /// For deal.II's broadcast (Boost serialization).
    template <class Archive>
    void
    serialize(Archive &ar, const unsigned int)
    {
      ar &path &bytes &crc;
    }

    bool
    operator==(const FileDigest &other) const
    {
      return path == other.path && bytes == other.bytes && crc == other.crc;
    }
  };



  /**
   * One checkpoint's directory as a method sees it: where its distributed files
   * go (a triangulation with its cells' data, records by cell), and on resume
   * whether this run has as many MPI ranks as the run that wrote it (then every
   * rank can read back its own part exactly; else the method redistributes).
   */
  struct CheckpointDirectory
  {
    std::string  path;
    unsigned int saved_ranks = 1;
    unsigned int n_ranks     = 1;

    std::string
    file(const std::string &name) const
    {
      return path + "/" + name;
    }

    bool
    same_ranks() const
    {
      return saved_ranks == n_ranks;
    }
  };
} // namespace hysteron

#endif
