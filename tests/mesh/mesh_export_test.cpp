#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "conform/io/mesh_export.hpp"
#include "conform/mesh/primitives.hpp"

namespace fs = std::filesystem;
using namespace conform;

namespace {

fs::path temp_dir(const std::string& name) {
  fs::path d = fs::temp_directory_path() /
               ("conform_mesh_export_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string slurp(const fs::path& p) {
  std::ifstream is(p, std::ios::binary);
  std::stringstream ss;
  ss << is.rdbuf();
  return ss.str();
}

}  // namespace

TEST(MeshExport, ParseFormat) {
  EXPECT_EQ(io::parse_mesh_format("ply"), io::MeshFormat::PlyBinary);
  EXPECT_EQ(io::parse_mesh_format("ply-ascii"), io::MeshFormat::PlyAscii);
  EXPECT_EQ(io::parse_mesh_format("obj"), io::MeshFormat::Obj);
  EXPECT_THROW(io::parse_mesh_format("stl"), std::invalid_argument);
}

TEST(MeshExport, AsciiPlyRoundTripsPositionsAndFaces) {
  const auto m = mesh::make_icosphere(1);
  const fs::path d = temp_dir("ascii");
  io::write_mesh(d / "s.ply", m, {io::MeshFormat::PlyAscii, false, false});
  std::ifstream is(d / "s.ply");
  std::string line;
  int nv = -1, nf = -1;
  while (std::getline(is, line) && line != "end_header") {
    std::sscanf(line.c_str(), "element vertex %d", &nv);
    std::sscanf(line.c_str(), "element face %d", &nf);
  }
  ASSERT_EQ(nv, m.vertex_count());
  ASSERT_EQ(nf, m.face_count());
  for (int i = 0; i < nv; ++i) {
    double x, y, z;
    is >> x >> y >> z;
    EXPECT_EQ(x, m.current(0, i));
    EXPECT_EQ(y, m.current(1, i));
    EXPECT_EQ(z, m.current(2, i));
  }
  for (int f = 0; f < nf; ++f) {
    int n, a, b, c;
    is >> n >> a >> b >> c;
    EXPECT_EQ(n, 3);
    EXPECT_EQ((mesh::Face{a, b, c}), m.faces[static_cast<std::size_t>(f)]);
  }
  // Only the target remains: no temporary files are left behind.
  EXPECT_EQ(std::distance(fs::directory_iterator(d), fs::directory_iterator()), 1);
  fs::remove_all(d);
}

TEST(MeshExport, BinaryPlySizeAndPayload) {
  const auto m = mesh::make_sheet(3, 2);
  const fs::path d = temp_dir("bin");
  io::write_mesh(d / "s.ply", m, {io::MeshFormat::PlyBinary, false, true});
  const std::string s = slurp(d / "s.ply");
  const auto end = s.find("end_header\n");
  ASSERT_NE(end, std::string::npos);
  const std::size_t body = s.size() - (end + 11);
  EXPECT_EQ(body, static_cast<std::size_t>(m.vertex_count()) * 5 * 8 +
                      static_cast<std::size_t>(m.face_count()) * 13);
  double x0;
  std::memcpy(&x0, s.data() + end + 11, 8);
  EXPECT_EQ(x0, m.current(0, 0));
  fs::remove_all(d);
}

TEST(MeshExport, ObjSubsetRenumbersVertices) {
  const auto m = mesh::make_sheet(2, 1);
  const fs::path d = temp_dir("obj");
  const std::int32_t faces[] = {3};
  io::write_mesh(d / "p.obj", m, {io::MeshFormat::Obj, false, false}, faces);
  std::ifstream is(d / "p.obj");
  std::string line;
  int v = 0, f = 0;
  while (std::getline(is, line)) {
    if (line.rfind("v ", 0) == 0) ++v;
    if (line.rfind("f ", 0) == 0) {
      ++f;
      int a, b, c;
      ASSERT_EQ(std::sscanf(line.c_str(), "f %d %d %d", &a, &b, &c), 3);
      EXPECT_TRUE(a >= 1 && a <= 3 && b >= 1 && b <= 3 && c >= 1 && c <= 3);
    }
  }
  EXPECT_EQ(v, 3);
  EXPECT_EQ(f, 1);
  fs::remove_all(d);
}

TEST(MeshExport, FailureLeavesTargetUntouchedAndThrows) {
  const auto m = mesh::make_sheet(1, 1);
  EXPECT_THROW(io::write_mesh("/nonexistent_dir_conform/x.ply", m), std::runtime_error);
  auto bad = m;
  bad.faces[0][1] = 99;
  const fs::path d = temp_dir("bad");
  EXPECT_THROW(io::write_mesh(d / "x.ply", bad), std::out_of_range);
  EXPECT_FALSE(fs::exists(d / "x.ply"));
  const std::int32_t faces[] = {7};
  EXPECT_THROW(io::write_mesh(d / "y.ply", m, {}, faces), std::out_of_range);
  fs::remove_all(d);
}
