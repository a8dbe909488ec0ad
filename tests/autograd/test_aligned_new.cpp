// The global operator new: autograd/aligned_new.cpp's 64-byte blocks from 32 bytes up; in an
// AddressSanitizer build (scripts/sanitize.sh) ASan's own, with no addressable slack past the
// request (aligned_new.cpp's rounding up to 64 bytes would hide overflows of up to 63 bytes).
#include <doctest/doctest.h>

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <memory>

#if defined(__SANITIZE_ADDRESS__)
#define GDSR_TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define GDSR_TEST_ASAN 1
#endif
#endif
#ifdef GDSR_TEST_ASAN
#include <sanitizer/asan_interface.h>
#endif

#ifndef GDSR_TEST_ASAN
TEST_CASE("aligned new: blocks of 32 bytes or more start on 64 bytes") {
  for (std::size_t n : {32, 33, 40, 64, 65, 1000, 4096 + 8}) {
    const std::unique_ptr<char[]> p(new char[n]);
    CHECK(reinterpret_cast<std::uintptr_t>(p.get()) % 64 == 0);
  }
}
#else
TEST_CASE("aligned new: under ASan the byte past the request is poisoned") {
  for (std::size_t n : {1, 31, 32, 33, 40, 63, 65, 1000}) {
    const std::unique_ptr<char[]> p(new char[n]);
    CHECK(__asan_region_is_poisoned(p.get(), n) == nullptr);  // the request is addressable
    CHECK(__asan_address_is_poisoned(p.get() + n) == 1);       // the next byte is not
  }
}
#endif
