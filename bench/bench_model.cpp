// GDSR network speed on a synthetic garment of the paper's size (35 x 35 = 1,225 LR
// vertices, 121 x 121 = 14,641 HR vertices, one UV square): inference per frame (all HR
// vertices, NoGradGuard) and a training step (forward on the HR vertices of 8 patches of
// 80 x 80 pixels of a 1024 raster, L1 on C_hat and G, backward), per preset.
// Counters: seconds and share of each block in the forward (features, H, E, A, field), the
// model's GFLOP per call (multiply-adds x 2 of its linear maps, from the architecture),
// GFLOP/s and the process's peak memory (MiB). Each benchmark makes one untimed call first.
// Float32 vs float64 inference (same weights): s/frame of each and the largest difference
// of the HR output G in mm. A dense Eigen GEMM is timed in the same run as the yardstick for
// a loaded machine (compare GFLOP/s ratios, not seconds). The program runs with passive
// OpenMP waiting unless OMP_WAIT_POLICY is set, and with large blocks kept in the heap
// (autograd/runtime.hpp). bench/preset_table.sh prints the per-preset table (one process per
// figure, so that peak memory is that figure's own); --reference_out / --reference_in check
// that a speed change leaves the output unchanged (see main).
#include <benchmark/benchmark.h>

#include "autograd/autograd.hpp"
#include "autograd/gemm_blocks.hpp"
#include "autograd/runtime.hpp"
#include "gdsr/geometry/correspondence.hpp"
#include "gdsr/model/gdsr_model.hpp"
#include "gdsr/model/model_config.hpp"
#include "gdsr/model/frames.hpp"
#include "tests/support/grid_garment.hpp"

#include <sys/resource.h>

#include <chrono>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

using namespace gdsr;

namespace {

// The tests' grid in the x-z plane with a smooth bump (metres).
GarmentMesh grid(int n, double size) {
  GarmentMesh g = gdsr_test::grid_garment(gdsr_test::GridSpec::square(n, size));
  for (int v = 0; v < g.V.rows(); ++v) g.V(v, 1) = 0.02 * std::sin(9 * g.V(v, 0)) * std::cos(7 * g.V(v, 2));
  return g;
}

struct Scene {
  GarmentMesh lr, hr;
  Correspondence corr;
  GarmentGraph graph;
  FrameInput in;
  HrRequest all, patches;
  Points3 G_target;
};

const Scene& scene() {
  static std::unique_ptr<Scene> s;
  if (s) return *s;
  s = std::make_unique<Scene>();
  const double size = 1.0;  // 1 m square: LR edges ~29 mm, HR ~8 mm (PD30 / PD10-like)
  s->lr = grid(35, size);
  s->hr = grid(121, size);
  s->corr = compute_correspondence(s->lr, s->hr);
  s->graph = build_graph(s->lr);
  s->in.C_t = s->lr.V;
  s->in.C_tm1 = s->lr.V;
  s->in.C_tm1.col(0).array() -= 0.003;
  s->in.C_tm2 = s->in.C_tm1;
  s->in.C_tm2.col(0).array() -= 0.002;
  s->in.Chat_tm1 = s->in.C_tm1;
  s->in.Chat_tm2 = s->in.C_tm2;
  s->all = hr_request_all(s->corr);
  // 8 patches of 80 x 80 raster pixels of 1024: HR vertices in 8 squares of 80/1024 of the side.
  std::vector<int> verts;
  const double w = 80.0 / 1024.0 * size;
  for (int p = 0; p < 8; ++p) {
    const double u0 = 0.05 + 0.11 * p, v0 = 0.1 + 0.09 * p;
    for (int v = 0; v < s->hr.V.rows(); ++v)
      if (s->hr.UV(v, 0) >= u0 && s->hr.UV(v, 0) < u0 + w && s->hr.UV(v, 1) >= v0 && s->hr.UV(v, 1) < v0 + w)
        verts.push_back(v);
  }
  s->patches = hr_request_subset(s->corr, verts);
  s->G_target = upsample(s->corr, s->lr.V);
  return *s;
}

int64_t block_macs(int64_t i, int64_t o) { return i * o + o * o; }
int64_t stack_macs(const std::vector<int64_t>& w) {
  int64_t n = 0;
  for (size_t k = 0; k + 1 < w.size(); ++k) n += block_macs(w[k], w[k + 1]);
  return n;
}

// Multiply-adds of the linear maps (the dominant cost), split by block.
struct Flops {
  double h = 0, e = 0, a = 0, field = 0;
  double total() const { return h + e + a + field; }
};
Flops model_flops(const ModelConfig& c, const GarmentGraph& g, int64_t faces_needed, int64_t samples) {
  const int64_t V = g.num_vertices, E1 = g.ring1_size(), E2 = g.ring2_size(), L = c.latent();
  const int64_t mid = c.node_encoder_pre.back();
  Flops f;
  f.h = double(V) *
            (stack_macs(c.node_encoder_pre) + mid * mid + stack_macs(c.node_encoder_post) + stack_macs(c.decoder)) +
        double(E1) * stack_macs(c.edge_encoder) +
        double(c.mp_steps) *
            (double(E1 + E2) * block_macs(3 * L, L) + double(V) * block_macs((c.layer_edge_mlps ? 4 : 3) * L, L));
  f.e = double(g.num_faces()) * (stack_macs(c.e_widths) + c.e_widths.back() * 9);
  f.a = double(faces_needed) * (stack_macs(c.a_widths) + 2 * c.a_widths.back() * c.field_params());
  double per_sample = 0;
  for (const auto& l : c.field_layers()) per_sample += (l.in == 3 ? 1.0 : 4.0) * double(l.in * l.out);
  f.field = double(samples) * per_sample;
  for (double* x : {&f.h, &f.e, &f.a, &f.field}) *x *= 2e-9;  // GFLOP
  return f;
}

// configs/ of the source tree this file belongs to (bench/../configs/).
std::string config_dir() {
  std::string f = __FILE__;
  f = f.substr(0, f.find_last_of('/'));
  return f.substr(0, f.find_last_of('/') + 1) + "configs/";
}

std::map<std::string, std::shared_ptr<GDSR<float>>>& models() {
  static std::map<std::string, std::shared_ptr<GDSR<float>>> m;
  return m;
}
GDSR<float>& model(const std::string& preset) {
  auto& m = models()[preset];
  if (!m) m = std::make_shared<GDSR<float>>(load_model_config(config_dir() + preset + ".json"));
  return *m;
}

// Peak resident memory of this process so far (MiB).
double peak_rss_mib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;
}

// Forward seconds per call of each block (H_s, E_s, A_s, field_s: compare with the PyTorch
// script's per-block figures), their shares, the model's GFLOP and rate, peak memory.
void set_counters(benchmark::State& st, const GdsrTimings& t, int iters, const Flops& f, double seconds_per_iter) {
  const double sum = t.features + t.h + t.e + t.a + t.field, n = std::max(1, iters);
  st.counters["features_%"] = 100 * t.features / sum;
  st.counters["H_%"] = 100 * t.h / sum;
  st.counters["E_%"] = 100 * t.e / sum;
  st.counters["A_%"] = 100 * t.a / sum;
  st.counters["field_%"] = 100 * t.field / sum;
  st.counters["H_s"] = t.h / n;
  st.counters["E_s"] = t.e / n;
  st.counters["A_s"] = t.a / n;
  st.counters["field_s"] = t.field / n;
  st.counters["GFLOP"] = f.total();
  st.counters["GFLOP/s"] = f.total() / seconds_per_iter;
  st.counters["peak_MiB"] = peak_rss_mib();
}

void BM_Inference(benchmark::State& st, const std::string& preset) {
  const Scene& s = scene();
  GDSR<float>& m = model(preset);
  {
    ag::NoGradGuard ng;  // warm-up: the heap grows once, as in the first frame of a roll-out
    m.forward(s.graph, s.in, &s.all, nullptr, nullptr);
  }
  GdsrTimings t;
  int iters = 0;
  double secs = 0;
  for (auto _ : st) {
    ag::NoGradGuard ng;
    const auto t0 = std::chrono::steady_clock::now();
    auto out = m.forward(s.graph, s.in, &s.all, nullptr, &t);
    benchmark::DoNotOptimize(out.G.data());
    secs += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ++iters;
  }
  const Flops f = model_flops(m.config(), s.graph, s.graph.num_faces(), s.all.size());
  set_counters(st, t, iters, f, secs / iters);
  st.counters["HR_vertices"] = s.all.size();
}

// Float64 twin of the float32 model (same weights), and the largest |G32 - G64| in mm.
GDSR<double>& model64(const std::string& preset, double* max_diff_mm) {
  static std::map<std::string, std::pair<std::shared_ptr<GDSR<double>>, double>> m;
  auto& e = m[preset];
  if (!e.first) {
    GDSR<float>& m32 = model(preset);
    e.first = std::make_shared<GDSR<double>>(m32.config());
    nn::copy_parameters(m32, *e.first);
    const Scene& s = scene();
    ag::NoGradGuard ng;
    const auto a = m32.forward(s.graph, s.in, &s.all, nullptr, nullptr);
    const auto b = e.first->forward(s.graph, s.in, &s.all, nullptr, nullptr);
    double d = 0;
    for (int64_t i = 0; i < a.G.numel(); ++i) d = std::max(d, std::abs(double(a.G.data()[i]) - b.G.data()[i]));
    e.second = 1e3 * d;
  }
  *max_diff_mm = e.second;
  return *e.first;
}

void BM_Inference64(benchmark::State& st, const std::string& preset) {
  const Scene& s = scene();
  double diff_mm = 0;
  GDSR<double>& m = model64(preset, &diff_mm);  // includes a first (warm-up) call
  GdsrTimings t;
  int iters = 0;
  double secs = 0;
  for (auto _ : st) {
    ag::NoGradGuard ng;
    const auto t0 = std::chrono::steady_clock::now();
    auto out = m.forward(s.graph, s.in, &s.all, nullptr, &t);
    benchmark::DoNotOptimize(out.G.data());
    secs += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ++iters;
  }
  const Flops f = model_flops(m.config(), s.graph, s.graph.num_faces(), s.all.size());
  set_counters(st, t, iters, f, secs / iters);
  st.counters["max_diff_f32_mm"] = diff_mm;
}

// Yardstick: one dense float32 GEMM (2048 x 512 x 4096, 8.6 GFLOP), threaded as the model's
// GEMMs are (row blocks over OpenMP, autograd/gemm_blocks.hpp).
void BM_DenseGemmReference(benchmark::State& st) {
  using M = ag::RowMat<float>;
  const M a = M::Random(2048, 512), b = M::Random(4096, 512);
  M c(2048, 4096);
  for (auto _ : st) {
    ag::gemm::tiles(a.rows(), b.rows(), a.cols(), [&](int64_t r0, int64_t r1, int64_t c0, int64_t c1) {
      c.block(r0, c0, r1 - r0, c1 - c0).noalias() = a.middleRows(r0, r1 - r0) * b.middleRows(c0, c1 - c0).transpose();
    });
    benchmark::DoNotOptimize(c.data());
  }
  st.counters["GFLOP/s"] =
      benchmark::Counter(2.0 * 2048 * 512 * 4096 * 1e-9, benchmark::Counter::kIsIterationInvariantRate);
}

void BM_TrainStep(benchmark::State& st, const std::string& preset) {
  const Scene& s = scene();
  GDSR<float>& m = model(preset);
  Points3 G_t(s.patches.size(), 3);
  for (int i = 0; i < s.patches.size(); ++i) {
    Eigen::RowVector3d p = Eigen::RowVector3d::Zero();
    for (int k = 0; k < 3; ++k) p += s.patches.bary(i, k) * s.lr.V.row(s.lr.F(s.patches.tri[i], k));
    G_t.row(i) = p;
  }
  const ag::Tensorf G_target = to_tensor<float>(G_t), C_target = to_tensor<float>(s.lr.V);
  nn::Rng noise(1);
  auto step = [&](GdsrTimings* t) {
    auto out = m.forward(s.graph, s.in, &s.patches, &noise, t);
    auto loss = ag::add(ag::l1_loss(out.C_hat, C_target), ag::l1_loss(out.G, G_target));
    loss.backward();
    m.zero_grad();
    return static_cast<int64_t>(out.faces.size());
  };
  step(nullptr);  // warm-up: the heap grows once, as in the first step of a training run
  GdsrTimings t;
  int iters = 0;
  double secs = 0;
  int64_t faces = 0;
  for (auto _ : st) {
    const auto t0 = std::chrono::steady_clock::now();
    faces = step(&t);
    secs += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ++iters;
  }
  Flops f = model_flops(m.config(), s.graph, faces, s.patches.size());
  f.h *= 3, f.e *= 3, f.a *= 3, f.field *= 3;  // backward ~ 2x forward
  set_counters(st, t, iters, f, secs / iters);
  st.counters["HR_samples"] = s.patches.size();
  st.counters["LR_faces_A"] = static_cast<double>(faces);
}

}  // namespace

BENCHMARK_CAPTURE(BM_Inference, tiny, std::string("tiny"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Inference, small, std::string("small"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Inference, paper, std::string("paper"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(3.0);
BENCHMARK_CAPTURE(BM_Inference64, tiny, std::string("tiny"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Inference64, small, std::string("small"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Inference64, paper, std::string("paper"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(3.0);
BENCHMARK(BM_DenseGemmReference)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_TrainStep, tiny, std::string("tiny"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_TrainStep, small, std::string("small"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_TrainStep, paper, std::string("paper"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(3.0);

// --reference_out=FILE writes the float32 inference output G (metres) of each preset's seeded
// model on the bench garment; --reference_in=FILE compares today's G with such a file and
// fails when any coordinate moved by 1e-5 m or more (a speed change must not change results).
int reference_check(const std::string& arg) {
  const bool write = arg.rfind("--reference_out=", 0) == 0;
  const std::string path = arg.substr(arg.find('=') + 1);
  std::FILE* f = std::fopen(path.c_str(), write ? "wb" : "rb");
  if (!f) {
    std::fprintf(stderr, "bench_model: cannot open %s\n", path.c_str());
    return 1;
  }
  int status = 0;
  for (const std::string preset : {"tiny", "small", "paper"}) {
    ag::NoGradGuard ng;
    const Scene& s = scene();
    const auto out = model(preset).forward(s.graph, s.in, &s.all, nullptr, nullptr);
    std::vector<double> g(out.G.data(), out.G.data() + out.G.numel()), ref(g.size());
    if (write) {
      std::fwrite(g.data(), sizeof(double), g.size(), f);
      continue;
    }
    if (std::fread(ref.data(), sizeof(double), ref.size(), f) != ref.size()) {
      std::fprintf(stderr, "bench_model: %s is too short for preset %s\n", path.c_str(), preset.c_str());
      status = 1;
      break;
    }
    double d = 0;
    for (size_t i = 0; i < g.size(); ++i) d = std::max(d, std::abs(g[i] - ref[i]));
    std::printf("%s: max |G - G_ref| = %.3g m\n", preset.c_str(), d);
    if (!(d < 1e-5)) status = 1;
  }
  std::fclose(f);
  return status;
}

int main(int argc, char** argv) {
  ag::configure_runtime(argv);
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]).rfind("--reference_", 0) == 0) return reference_check(argv[i]);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::AddCustomContext("omp_wait_policy", ag::openmp_wait_policy());
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
