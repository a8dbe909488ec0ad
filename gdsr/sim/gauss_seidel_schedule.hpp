#pragma once
// Gauss-Seidel over a fixed list of constraints on two threads, with the one-thread result
// bit for bit.
//
// In one Gauss-Seidel pass, constraint k reads and moves a few vertices after every earlier
// constraint on those vertices. Give each constraint a level, one more than the levels of the
// last earlier constraints on its vertices: constraints of one level share no vertex, and any
// order that runs the levels in turn gives the sequential result exactly. The edges of the
// 10 mm t-shirt (13,428 vertices on the salsa body), sorted by vertex, have 735 levels for
// 40,018 edges, so a pass is mostly independent work. Each of two threads takes the
// constraints of half the vertex numbers, level by level, and before a constraint that follows
// one of the other thread's, waits until the other thread has done it (a counter per thread):
// only 361 of thread 1's edges ever wait. One stretch pass over the t-shirt's edges (15.2k
// vertices on the CMU 01_01 body): 0.83 ms on one thread, 0.54 ms on two
// (bench/bench_gauss_seidel.cpp). Tried on the self-contact pairs too, it lost: they change
// every substep, and planning them cost more than the second thread saved.
#include <array>
#include <atomic>
#include <thread>
#include <vector>

#include <omp.h>

namespace sim {

class GaussSeidelSchedule {
 public:
  // items[k]: the vertices (< num_vertices; -1 for none) constraint k moves, in the order of
  // the sequential pass: an edge's two, a vertex-triangle or an edge-edge pair's four.
  using Item = std::array<int, 4>;
  void plan(const std::vector<Item>& items, int num_vertices);
  int size() const { return count_; }
  int levels() const { return levels_; }
  // Constraints of list t (0, 1) that wait for the other list at least once (for tests).
  int waits(int t) const;
  // Each item's slot: list 0's items take slots 0, 1, ... in the order thread 0 runs them, list
  // 1's the rest, so data a caller stores by slot is read front to back by each thread (in
  // level order the items jump about the mesh, and data stored by item was read at random).
  int slot(int item) const { return slot_of_[item]; }

  // fn(item, slot) for every item: on two threads if the region gets them, else items 0, 1, ...
  // in turn; either way with the sequential pass's result. fn must not throw.
  template <class Fn> void run(Fn&& fn) const {
    // Items of each list finished, a cache line each: a counter beside the one the other thread
    // writes after every item would be fetched from the other core at every read.
    struct alignas(64) Counter {
      std::atomic<int> n{0};
    };
    Counter done[2];
#pragma omp parallel num_threads(2) if (omp_get_max_threads() > 1)
    {
      if (omp_get_num_threads() == 1) {
        for (int k = 0; k < count_; ++k) fn(k, slot_of_[k]);
      } else {
        const int t = omp_get_thread_num();
        const int begin = t ? first_[1] : 0, end = t ? count_ : first_[1];
        const std::atomic<int>& other = done[1 - t].n;
        int seen = 0;  // the other's count when last read: read again only to wait beyond it
        for (int p = begin; p < end; ++p) {
          const Step& s = steps_[p];
          for (int spin = 0; seen < s.wait; ++spin) {
            if (spin > 64) std::this_thread::yield();  // the other thread may not be running
            seen = other.load(std::memory_order_acquire);
          }
          fn(s.item, p);
          done[t].n.store(p - begin + 1, std::memory_order_release);
        }
      }
    }
  }

 private:
  struct Step {
    int item;
    int wait;  // the other list's items that must be finished first (a count, 0: none)
  };
  std::vector<Step> steps_;  // by slot: list 0, then list 1 from first_[1]
  std::vector<int> slot_of_;
  int first_[2] = {0, 0};
  int count_ = 0, levels_ = 0;
};

}  // namespace sim
