#ifndef hysteron_base_checkpoint_h
#define hysteron_base_checkpoint_h

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
  /**
   * The binary stream of one rank's part of a checkpoint. A method writes its
   * state with put() in named sections; CheckpointReader reads it back in the
   * same order and checks every section name, so that a checkpoint of another
   * version or method is refused with a message instead of being misread.
   * Values are stored bit for bit (trivially copyable types: double, integers,
   * deal.II's Point, Tensor and SymmetricTensor), so that a resumed run
   * continues from exactly the state of the interrupted one.
   */
  class CheckpointWriter
  {
  public:
    explicit CheckpointWriter(std::ostream &out)
      : out(out)
    {}

    /// Start a section: the reader must ask for the same name here.
    void
    section(const std::string &name)
    {
      put(std::string("section:") + name);
    }

    template <typename T>
    void
    put(const T &value)
    {
      static_assert(std::is_trivially_copyable_v<T>, "only trivially copyable values");
      out.write(reinterpret_cast<const char *>(&value), sizeof(T));
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
      if constexpr (std::is_trivially_copyable_v<T>)
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
    CheckpointReader(std::istream &in, const std::string &filename)
      : in(in)
      , filename(filename)
    {}

    /// Check that the next section is @p name.
    void
    section(const std::string &name);

    template <typename T>
    void
    get(T &value)
    {
      static_assert(std::is_trivially_copyable_v<T>, "only trivially copyable values");
      read(reinterpret_cast<char *>(&value), sizeof(T));
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
      if constexpr (std::is_trivially_copyable_v<T>)
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
} // namespace hysteron

#endif
