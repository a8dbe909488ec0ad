// The browser viewer in headless Chromium: the report's viewer/ (write_viewer) served over
// HTTP next to export/ (export_rollout) loads every file (no 404), reports "ready" with three
// garments and no error, and a screenshot shows the three garments in their colours, left
// to right. When Chromium or three.js (npm) is missing the test says "SKIPPED" (ctest
// reports it as skipped); scripts/setup.sh installs both.
#include <doctest/doctest.h>

#include "gdsr/error.hpp"
#include "infer/export_rollout.hpp"
#include "infer/report_viewer.hpp"
#include "tests/support/data_fixtures.hpp"

#include <opencv2/imgcodecs.hpp>

#include <arpa/inet.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <fstream>
#include <netinet/in.h>
#include <sstream>
#include <sys/socket.h>
#include <thread>
#include <unistd.h>

namespace {

std::string on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::stringstream ss(path ? path : "");
  for (std::string dir; std::getline(ss, dir, ':');)
    if (!dir.empty() && ::access((dir + "/" + program).c_str(), X_OK) == 0) return dir + "/" + program;
  return "";
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

bool port_open(int port) {
  const int s = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  const bool ok = ::connect(s, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
  ::close(s);
  return ok;
}

// python3's http.server on 127.0.0.1 serving dir, on a free port the system picks (read from
// its log), stopped (by its pid) on destruction.
struct HttpServer {
  int pid = -1, port = -1;
  HttpServer(const std::string& dir, const std::string& log) {
    const std::string pidfile = log + ".pid";
    const std::string cmd = "python3 -u -m http.server 0 --bind 127.0.0.1 -d '" + dir + "' >'" + log +
                            "' 2>&1 & echo $! >'" + pidfile + "'";
    if (std::system(cmd.c_str()) != 0) return;
    pid = std::atoi(slurp(pidfile).c_str());
    const std::string key = " port ";  // "Serving HTTP on 127.0.0.1 port 40123 (http://...) ..."
    for (int i = 0; i < 200 && port < 0; ++i) {
      const std::string text = slurp(log);
      const size_t at = text.find(key);
      if (at != std::string::npos && text.find(" (", at) != std::string::npos)
        port = std::atoi(text.c_str() + at + key.size());
      if (port < 0) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }
  ~HttpServer() {
    if (pid > 0) ::kill(pid, SIGTERM);
  }
};

// Saturated pixels whose hue (degrees) lies in [hue_lo, hue_hi]: a garment colour under any
// lighting. Their count and mean column.
struct Blob {
  int count = 0;
  double mean_x = 0;
};
Blob blob(const cv::Mat& img, int hue_lo, int hue_hi) {
  Blob b;
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x) {
      const cv::Vec3b p = img.at<cv::Vec3b>(y, x);
      const int mx = std::max({p[0], p[1], p[2]}), mn = std::min({p[0], p[1], p[2]});
      if (mx < 40 || mx - mn < 50) continue;  // dark or grey
      const double r = p[2], g = p[1], bl = p[0], d = mx - mn;
      double h = mx == p[2]   ? 60 * std::fmod((g - bl) / d, 6.0)
                 : mx == p[1] ? 60 * ((bl - r) / d + 2)
                              : 60 * ((r - g) / d + 4);
      if (h < 0) h += 360;
      if (h >= hue_lo && h <= hue_hi) ++b.count, b.mean_x += x;
    }
  if (b.count) b.mean_x /= b.count;
  return b;
}

}  // namespace

TEST_CASE("report viewer: headless Chromium loads the exports and shows three garments") {
  const std::string chromium = on_path("chromium");
  const std::string viewer_src = std::string(GDSR_SOURCE_DIR) + "/viewer";
  if (chromium.empty() || on_path("python3").empty()) {
    MESSAGE("SKIPPED: chromium or python3 is not installed (run scripts/setup.sh)");
    WARN_MESSAGE(false, "the viewer test did not run");
    return;
  }
  if (!std::filesystem::exists(viewer_src + "/node_modules/three/build/three.module.js")) {
    MESSAGE("SKIPPED: three.js is not installed in viewer/node_modules (run scripts/setup.sh)");
    WARN_MESSAGE(false, "the viewer test did not run");
    return;
  }
  const gdsr::Dataset d = gdsr_test::wave_dataset(6);
  std::vector<gdsr::Points3> G(d.hr_frames.begin(), d.hr_frames.end());
  gdsr_test::TempDir dir("report_viewer");
  gdsr::RolloutExportOptions opt;
  opt.formats.obj = false;
  gdsr::export_rollout(dir / "report/export", d, G, 0, opt);
  const auto files = gdsr::write_viewer(dir / "report", viewer_src);
  CHECK(files.size() == 6);

  const std::string http_log = dir / "http.log";
  HttpServer server(dir / "report", http_log);
  REQUIRE(server.pid > 0);
  REQUIRE(server.port > 0);
  REQUIRE(port_open(server.port));
  const std::string url = "http://127.0.0.1:" + std::to_string(server.port) + "/viewer/?frame=3";
  const std::string flags =
      " --headless --no-sandbox --disable-gpu --use-gl=swiftshader --enable-unsafe-swiftshader "
      "--virtual-time-budget=8000 --window-size=1200,600 ";
  const std::string dom = dir / "dom.html";
  const std::string dump = "timeout 90 '" + chromium + "'" + flags + "--dump-dom '" + url + "' >'" + dom + "' 2>'" +
                           (dir / "chromium.log") + "'";
  CHECK(std::system(dump.c_str()) == 0);
  const std::string html = slurp(dom);
  CHECK_MESSAGE(html.find("ready: 3 garments, 6 frames") != std::string::npos, html.substr(0, 2000));
  CHECK(html.find("error:") == std::string::npos);
  CHECK(html.find("frame 3") != std::string::npos);

  const std::string shot = dir / "shot.png";
  const std::string snap =
      "timeout 90 '" + chromium + "'" + flags + "--screenshot='" + shot + "' '" + url + "' >/dev/null 2>&1";
  CHECK(std::system(snap.c_str()) == 0);
  const std::string log = slurp(http_log);
  CHECK_MESSAGE(log.find(" 404 ") == std::string::npos, log);
  CHECK(log.find("GET /export/hr.bin") != std::string::npos);
  const cv::Mat img = cv::imread(shot);
  REQUIRE_FALSE(img.empty());
  // Orange (LR), blue (GDSR), green (HR) from left to right.
  const Blob lr = blob(img, 15, 45), gdsr_b = blob(img, 200, 230), hr = blob(img, 100, 140);
  CHECK(lr.count > 500);
  CHECK(gdsr_b.count > 500);
  CHECK(hr.count > 500);
  CHECK(lr.mean_x < gdsr_b.mean_x);
  CHECK(gdsr_b.mean_x < hr.mean_x);

  CHECK_THROWS_WITH_AS(gdsr::write_viewer(dir / "r2", dir / "nowhere"), doctest::Contains("index.html"), gdsr::Error);
}
