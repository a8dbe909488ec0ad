// nn::Rng state round trip: a generator restored from state() continues the same stream,
// including a pending Box-Muller spare.
#include <doctest/doctest.h>

#include "nn/rng.hpp"

TEST_CASE("rng: set_state continues the stream exactly with a pending Gaussian spare") {
  nn::Rng a(42);
  for (int i = 0; i < 7; ++i) a.normal(0, 1);  // odd count: a spare is pending
  const nn::Rng::State st = a.state();
  CHECK(st.has_spare);
  nn::Rng b(1);
  b.set_state(st);
  for (int i = 0; i < 20; ++i) {
    CHECK(a.normal(0.5, 2.0) == b.normal(0.5, 2.0));
    CHECK(a.next() == b.next());
  }
  nn::Rng c(1);
  CHECK(c.next() != b.next());  // a fresh generator is elsewhere in its stream
}
