// Planted for tests/check_omp_threads.cmake: a region that takes two threads whatever
// OMP_NUM_THREADS says. Never compiled.
void violation(int n, double* x) {
#pragma omp parallel for num_threads(2)
  for (int i = 0; i < n; ++i) x[i] *= 2;
}
