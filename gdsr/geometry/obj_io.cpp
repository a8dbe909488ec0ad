#include "gdsr/geometry/obj_io.hpp"

#include "gdsr/error.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <signal.h>
#include <unistd.h>
#include <vector>

namespace gdsr {
namespace {

[[noreturn]] void fail_at(const std::string& path, size_t line, const std::string& msg) {
  gdsr::fail("obj: " + path + ":" + std::to_string(line), msg);
}

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) gdsr::fail("obj", "cannot open " + path + ": " + std::strerror(errno));  // missing, permission, ...
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r'; }

struct LineParser {
  const char* p;
  const char* end;
  const std::string& path;
  size_t line;

  void skip() {
    while (p < end && is_space(*p)) ++p;
  }
  bool done() {
    skip();
    return p >= end;
  }
  double number() {
    skip();
    if (p >= end) fail_at(path, line, "missing number");
    char* q = nullptr;
    std::string tok(p, std::find_if(p, end, is_space));
    double v = std::strtod(tok.c_str(), &q);
    if (q == tok.c_str() || *q != '\0') fail_at(path, line, "malformed number '" + tok + "'");
    if (!std::isfinite(v)) fail_at(path, line, "non-finite coordinate '" + tok + "'");
    p += tok.size();
    return v;
  }
  // One face corner "v", "v/vt", "v/vt/vn" or "v//vn"; returns 1-based/negative raw indices,
  // 0 for an absent vt.
  void corner(long& v, long& vt) {
    std::string tok(p, std::find_if(p, end, is_space));
    p += tok.size();
    const char* s = tok.c_str();
    char* q = nullptr;
    v = std::strtol(s, &q, 10);
    if (q == s || (*q != '\0' && *q != '/') || v == 0) fail_at(path, line, "malformed face corner '" + tok + "'");
    vt = 0;
    if (*q == '/') {
      const char* r = q + 1;
      if (*r != '/') {
        vt = std::strtol(r, &q, 10);
        if (q == r || (*q != '\0' && *q != '/') || vt == 0) fail_at(path, line, "malformed face corner '" + tok + "'");
      } else {
        q = const_cast<char*>(r);
      }
      if (*q == '/') {
        const char* n = q + 1;
        std::strtol(n, &q, 10);
        if (q == n || *q != '\0') fail_at(path, line, "malformed face corner '" + tok + "'");
      }
    }
  }
};

int resolve(long idx, size_t count, const std::string& path, size_t line, const char* what) {
  long i = idx > 0 ? idx - 1 : static_cast<long>(count) + idx;
  if (i < 0 || i >= static_cast<long>(count))
    fail_at(path, line,
            std::string(what) + " index " + std::to_string(idx) + " out of range (have " + std::to_string(count) + ")");
  return static_cast<int>(i);
}

std::string fmt(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", x);
  return buf;
}

}  // namespace

GarmentMesh as_written_obj(const GarmentMesh& mesh) {
  auto round_trip = [](double x) { return std::strtod(fmt(x).c_str(), nullptr); };
  GarmentMesh m = mesh;
  m.V = mesh.V.unaryExpr(round_trip);
  m.UV = mesh.UV.unaryExpr(round_trip);
  return m;
}

ObjData read_obj(const std::string& path) { return parse_obj(read_all(path), path); }

ObjData parse_obj(const std::string& text, const std::string& path) {
  std::vector<double> v, vt;
  std::vector<int> f, ft;
  std::vector<long> cv, ct;
  size_t line = 0;
  const char* p = text.data();
  const char* end = p + text.size();
  while (p < end) {
    const char* eol = std::find(p, end, '\n');
    ++line;
    LineParser lp{p, eol, path, line};
    lp.skip();
    if (lp.p < eol && *lp.p != '#') {
      const char* key = lp.p;
      while (lp.p < eol && !is_space(*lp.p)) ++lp.p;
      const std::string k(key, lp.p);
      if (k == "v") {
        for (int d = 0; d < 3; ++d) v.push_back(lp.number());
        // an optional w or vertex colour may follow; ignore it
      } else if (k == "vt") {
        vt.push_back(lp.number());
        vt.push_back(lp.done() ? 0.0 : lp.number());
      } else if (k == "f") {
        cv.clear();
        ct.clear();
        while (!lp.done()) {
          long a, b;
          lp.corner(a, b);
          cv.push_back(a);
          ct.push_back(b);
        }
        if (cv.size() < 3) fail_at(path, line, "face with fewer than 3 corners");
        const size_t nv = v.size() / 3, nt = vt.size() / 2;
        for (size_t c = 1; c + 1 < cv.size(); ++c) {
          for (size_t k2 : {size_t(0), c, c + 1}) {
            f.push_back(resolve(cv[k2], nv, path, line, "vertex"));
            ft.push_back(ct[k2] == 0 ? -1 : resolve(ct[k2], nt, path, line, "texture"));
          }
        }
      }
    }
    p = eol < end ? eol + 1 : end;
  }
  if (v.empty()) gdsr::fail("obj", std::string(path) + ": no vertices (empty mesh)");
  if (f.empty()) gdsr::fail("obj", std::string(path) + ": no faces (empty mesh)");
  ObjData out;
  out.V = Eigen::Map<Points3>(v.data(), static_cast<long>(v.size() / 3), 3);
  out.VT = Eigen::Map<Points2>(vt.data(), static_cast<long>(vt.size() / 2), 2);
  out.F = Eigen::Map<Faces>(f.data(), static_cast<long>(f.size() / 3), 3);
  out.FT = Eigen::Map<Faces>(ft.data(), static_cast<long>(ft.size() / 3), 3);
  return out;
}

TriMesh read_obj_mesh(const std::string& path) {
  ObjData d = read_obj(path);
  return TriMesh{std::move(d.V), std::move(d.F)};
}

GarmentMesh garment_from_obj(const ObjData& obj, const std::string& what) {
  if (!obj.has_uv()) gdsr::fail("obj", std::string(what) + ": every face needs texture (vt) indices for a garment");
  GarmentMesh g;
  g.V = obj.V;
  g.F = obj.F;
  g.UV = obj.VT;
  g.FUV = obj.FT;
  g.uv_to_vertex.assign(g.UV.rows(), -1);
  for (int f = 0; f < g.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      int& m = g.uv_to_vertex[g.FUV(f, k)];
      if (m >= 0 && m != g.F(f, k))
        gdsr::fail("obj", std::string(what) + ": texture vertex " + std::to_string(g.FUV(f, k) + 1) +
                              " is used with two different vertices (" + std::to_string(m + 1) + ", " +
                              std::to_string(g.F(f, k) + 1) + ")");
      m = g.F(f, k);
    }
  for (size_t u = 0; u < g.uv_to_vertex.size(); ++u)
    if (g.uv_to_vertex[u] < 0)
      gdsr::fail("obj", std::string(what) + ": texture vertex " + std::to_string(u + 1) + " is not used by any face");
  return g;
}

GarmentMesh read_obj_garment(const std::string& path) { return garment_from_obj(read_obj(path), path); }

void write_file_atomic(const std::string& path, const std::string& bytes) {
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) gdsr::fail("write", "cannot create " + tmp);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.flush();
    if (!out) {
      std::remove(tmp.c_str());
      gdsr::fail("write", "failed writing " + tmp);
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    gdsr::fail("write", "cannot rename " + tmp + " to " + path);
  }
}

void remove_stale_temps(const std::string& dir, const std::vector<std::string>& names) {
  namespace fs = std::filesystem;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string n = e.path().filename().string();
    for (const std::string& name : names) {
      const std::string prefix = name + ".tmp.";
      if (n.size() <= prefix.size() || n.compare(0, prefix.size(), prefix) != 0) continue;
      const std::string pid = n.substr(prefix.size());
      if (pid.size() > 9 || pid.find_first_not_of("0123456789") != std::string::npos) continue;
      if (::kill(static_cast<pid_t>(std::stol(pid)), 0) == 0 || errno != ESRCH) continue;  // still running
      if (e.is_directory(ec)) {
        bool only_files = true;
        for (const auto& f : fs::directory_iterator(e.path(), ec)) only_files = only_files && !f.is_directory(ec);
        if (!only_files) continue;
      }
      fs::remove_all(e.path(), ec);
    }
  }
}

void write_obj(const std::string& path, const TriMesh& mesh) {
  std::string s;
  s.reserve(static_cast<size_t>(mesh.V.rows()) * 40 + static_cast<size_t>(mesh.F.rows()) * 24);
  for (int i = 0; i < mesh.V.rows(); ++i)
    s += "v " + fmt(mesh.V(i, 0)) + " " + fmt(mesh.V(i, 1)) + " " + fmt(mesh.V(i, 2)) + "\n";
  for (int f = 0; f < mesh.F.rows(); ++f)
    s += "f " + std::to_string(mesh.F(f, 0) + 1) + " " + std::to_string(mesh.F(f, 1) + 1) + " " +
         std::to_string(mesh.F(f, 2) + 1) + "\n";
  write_file_atomic(path, s);
}

void write_obj(const std::string& path, const GarmentMesh& mesh) {
  std::string s;
  s.reserve(static_cast<size_t>(mesh.V.rows()) * 40 + static_cast<size_t>(mesh.UV.rows()) * 30 +
            static_cast<size_t>(mesh.F.rows()) * 40);
  for (int i = 0; i < mesh.V.rows(); ++i)
    s += "v " + fmt(mesh.V(i, 0)) + " " + fmt(mesh.V(i, 1)) + " " + fmt(mesh.V(i, 2)) + "\n";
  for (int i = 0; i < mesh.UV.rows(); ++i) s += "vt " + fmt(mesh.UV(i, 0)) + " " + fmt(mesh.UV(i, 1)) + "\n";
  for (int f = 0; f < mesh.F.rows(); ++f) {
    s += "f";
    for (int k = 0; k < 3; ++k) s += " " + std::to_string(mesh.F(f, k) + 1) + "/" + std::to_string(mesh.FUV(f, k) + 1);
    s += "\n";
  }
  write_file_atomic(path, s);
}

}  // namespace gdsr
