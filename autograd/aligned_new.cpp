// Replaces the global operator new so that every heap block of 32 bytes or more starts on a
// 64-byte boundary (the widest vector register). Eigen's vectorised reductions split a row
// into an unaligned head and aligned packets, so their rounding depended on where malloc
// happened to place a tensor: the same training step gave different last bits in another
// process (measured: a resumed run drifted from an uninterrupted one on configs/small.json).
// With one alignment for all large blocks the arithmetic is the same in every process.
// Linked into every program through gdsr_autograd (the linker takes this object for the
// first undefined operator new). Blocks come from malloc / aligned_alloc, freed with free.
// Not in a sanitizer build (-DGDSR_SANITIZE=address, scripts/sanitize.sh): the ASan runtime
// already defines operator new when the linker reaches this archive member, so ASan's own
// allocator serves new (exact block sizes for its overflow checks, 16-byte alignment).
#include <cstdlib>
#include <new>

void* operator new(std::size_t n) {
  void* p = n >= 32 ? std::aligned_alloc(64, (n + 63) & ~std::size_t{63}) : std::malloc(n ? n : 1);
  if (!p) throw std::bad_alloc();
  return p;
}
void* operator new[](std::size_t n) { return ::operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
