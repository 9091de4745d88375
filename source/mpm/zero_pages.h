#ifndef hysteron_source_mpm_zero_pages_h
#define hysteron_source_mpm_zero_pages_h

#include <deal.II/base/exceptions.h>

#include <sys/mman.h>

#include <cerrno>
#include <cstddef>
#include <cstring>
#include <string>
#include <type_traits>
#include <utility>

namespace hysteron
{
  namespace MPM
  {
    /**
     * An array of n zero-initialised values whose memory is taken from the
     * operating system page by page, when a page is first written: an anonymous
     * mapping (mmap, MAP_NORESERVE) instead of a std::vector, which would write
     * every zero.
     *
     * The grid keeps its nodal data in one dense box per rank (so that a
     * point's support nodes are a base index plus constant strides), and the
     * box of a rank's part of a space-filling curve can be much larger than
     * the part. With these arrays a rank's memory follows the nodes it reaches
     * (the pages they lie in), not its box. Reading a page never written costs
     * nothing either (the kernel's shared zero page). @p sparse asks the kernel
     * not to back the array with huge pages, which would take 2 MB where a few
     * nodes are used.
     */
    template <typename T>
    class ZeroPages
    {
      static_assert(std::is_trivially_copyable_v<T>, "plain values only");

    public:
      ZeroPages() = default;

      ~ZeroPages()
      {
        release();
      }

      ZeroPages(const ZeroPages &) = delete;
      ZeroPages &
      operator=(const ZeroPages &) = delete;

      /// @p n zeros (the previous contents are given back).
      void
      reset(const std::size_t n, const bool sparse = false)
      {
        release();
        n_values = n;
        if (n == 0)
          return;
        bytes  = n * sizeof(T);
        void *p = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
        AssertThrow(p != MAP_FAILED,
                    dealii::ExcMessage("cannot map " + std::to_string(bytes) + " bytes for the MPM grid: " +
                                       std::strerror(errno)));
        if (sparse)
          ::madvise(p, bytes, MADV_NOHUGEPAGE);
        values = static_cast<T *>(p);
      }

      std::size_t
      size() const
      {
        return n_values;
      }

      T *
      data()
      {
        return values;
      }

      const T *
      data() const
      {
        return values;
      }

      T &
      operator[](const std::size_t i)
      {
        return values[i];
      }

      const T &
      operator[](const std::size_t i) const
      {
        return values[i];
      }

    private:
      void
      release()
      {
        if (values != nullptr)
          ::munmap(values, bytes);
        values   = nullptr;
        n_values = 0;
        bytes    = 0;
      }

      T          *values   = nullptr;
      std::size_t n_values = 0;
      std::size_t bytes    = 0;
    };
  } // namespace MPM
} // namespace hysteron

#endif
