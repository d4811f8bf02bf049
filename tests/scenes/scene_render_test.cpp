// `conform run`'s pictures, video and run.glb, on a short tear-opening (60 steps: the stroke
// and its first opening, frames at steps 0, 30, 60; two pictures, where the wound changes: the
// first step with a wound and the last): the pictures have the requested size and
// show something, the physics and geometric panels differ where the wound is, the wound bed's
// colour shows through the open wound only once it is open, run.glb reads back through assimp
// with each frame's vertex and face counts of the PLY frames (read by assimp too), and f3d opens
// it. A run without f3d on PATH still succeeds, with a warning. The renders need f3d, xvfb and
// ffmpeg (scripts/deps.sh); conform starts its own Xvfb when there is no display, and a killed
// run leaves none behind, nor the f3d it started early for the last frame.
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <assimp/Importer.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

constexpr int kWidth = 200, kHeight = 150;

const fs::path& run_dir() {
  // One folder per process: ctest runs each test in its own process, maybe in parallel.
  static const fs::path dir =
      fs::temp_directory_path() / ("conform_scene_render_test_" + std::to_string(::getpid()));
  return dir;
}

int run_conform(const std::string& args, const fs::path& out, const std::string& env = "") {
  const fs::path conform = fs::path(CONFORM_BINARY_DIR) / "scenes" / "conform";
  fs::remove_all(out);
  const std::string cmd = env + " " + conform.string() + " run tear-opening --steps 60 --out " +
                          out.string() + " " + args + " > " + out.string() + ".log 2>&1";
  return std::system(cmd.c_str());
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A PNG's size from its IHDR chunk (bytes 16-23, big-endian).
std::array<int, 2> png_size(const fs::path& p) {
  const std::string s = read_text(p);
  if (s.size() < 24 || s.compare(1, 3, "PNG") != 0) return {0, 0};
  const auto be = [&](std::size_t at) {
    int v = 0;
    for (std::size_t i = 0; i < 4; ++i) v = (v << 8) | static_cast<unsigned char>(s[at + i]);
    return v;
  };
  return {be(16), be(20)};
}

// The pixels as RGB bytes, decoded by ffmpeg (an independent decoder); `crop` ("w:h:x:y"),
// when given, cuts a rectangle out first.
std::vector<unsigned char> pixels(const fs::path& p, const std::string& crop = "") {
  const std::string cmd = "ffmpeg -loglevel error -i " + p.string() +
                          (crop.empty() ? "" : " -vf crop=" + crop) +
                          " -f rawvideo -pix_fmt rgb24 -";
  std::vector<unsigned char> out;
  FILE* f = popen(cmd.c_str(), "r");
  if (!f) return out;
  unsigned char buf[65536];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;)
    out.insert(out.end(), buf, buf + n);
  pclose(f);
  return out;
}

// Panel k of a strip (ffmpeg's crop: width:height:x:y).
std::string panel_crop(int k) {
  return std::to_string(kWidth) + ":" + std::to_string(kHeight) + ":" + std::to_string(k * kWidth) +
         ":0";
}

// Pixels that are not the white background.
int foreground(const std::vector<unsigned char>& rgb) {
  int n = 0;
  for (std::size_t i = 0; i + 2 < rgb.size(); i += 3) n += rgb[i] + rgb[i + 1] + rgb[i + 2] < 720;
  return n;
}

// Pixels of the wound bed's dark crimson (lit, about (99, 41, 53): red well above green and
// blue, not bright).
int wound_bed(const std::vector<unsigned char>& rgb) {
  int n = 0;
  for (std::size_t i = 0; i + 2 < rgb.size(); i += 3) {
    const int r = rgb[i], g = rgb[i + 1], b = rgb[i + 2];
    n += r > 60 && r < 200 && g < 80 && r > g + 35 && r > b + 30;
  }
  return n;
}

class SceneRender : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    rc_ = run_conform("--set render.width=" + std::to_string(kWidth) +
                          " --set render.height=" + std::to_string(kHeight) +
                          " --set render.pictures=2 --set outputs.plots=false",
                      run_dir());
    if (rc_ != 0)  // the run's own words, before TearDownTestSuite removes them
      std::printf("conform exited %d:\n%s\n", rc_, read_text(run_dir().string() + ".log").c_str());
    summary_ = Json::parse(read_text(run_dir() / "summary.json"), nullptr, false);
    first_ = first_wound_step(run_dir() / "metrics.csv");
  }
  // The first step whose physical tear has two points (a wound to draw), from metrics.csv.
  static int first_wound_step(const fs::path& csv) {
    std::ifstream in(csv);
    std::string line;
    std::getline(in, line);
    const auto column = [](const std::string& row, int k) {
      std::size_t at = 0;
      for (int i = 0; i < k; ++i) at = row.find(',', at) + 1;
      return std::atof(row.c_str() + at);
    };
    int points = 0;  // the header's column of physics_tear_points
    for (std::size_t at = 0; line.compare(at, 19, "physics_tear_points") != 0; ++points)
      at = line.find(',', at) + 1;
    while (std::getline(in, line))
      if (column(line, points) >= 2) return int(std::lround(column(line, 0) * 60));
    return -1;
  }
  // pictures/step_STEP.png's STEP.
  static std::string stem(int step) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "%06d", step);
    return buf;
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(run_dir(), ec);
    fs::remove(run_dir().string() + ".log", ec);
  }
  static int rc_;
  static Json summary_;
  static int first_;
};
int SceneRender::rc_ = -1;
Json SceneRender::summary_;
int SceneRender::first_ = -1;

TEST_F(SceneRender, RunSucceedsAndReportsItsRenders) {
  ASSERT_EQ(rc_, 0) << read_text(run_dir().string() + ".log");
  ASSERT_TRUE(summary_.is_object());
  const Json& r = summary_["render"];
  EXPECT_TRUE(r["warnings"].empty()) << r["warnings"].dump();
  // The wound appears during the stroke (step 30 on) and changes to the end.
  ASSERT_GT(first_, 30);
  ASSERT_LT(first_, 40);
  EXPECT_EQ(r["pictures"],
            Json::array({"pictures/step_" + stem(first_) + ".png", "pictures/step_000060.png"}));
  EXPECT_EQ(r["chosen"]["by"], "wound");
  EXPECT_EQ(r["chosen"]["from_step"], first_);
  EXPECT_EQ(r["chosen"]["settled_step"], 60);
  EXPECT_EQ(r["video"], "run.gif");
  EXPECT_EQ(r["camera"]["aimed_at"], "event");
  EXPECT_GT(r["render_ms_per_picture"].get<double>(), 0);
  EXPECT_GT(r["sim_ms_per_step"].get<double>(), 0);
  // The last frame's f3d started with the first frame (f3d_render.hpp); the other frame's ran
  // from conform's own f3d jobs (recorded in render.sh).
  EXPECT_EQ(r["timings"]["f3d_started_early"], 1);
  EXPECT_FALSE(r.contains("notes")) << r["notes"].dump();
}

TEST_F(SceneRender, PicturesHaveTheRequestedSizeAndShowTheWound) {
  ASSERT_EQ(rc_, 0);
  for (const std::string& step : {stem(first_), std::string("000060")}) {
    const fs::path side = run_dir() / "pictures" / ("step_" + step + ".png");
    // Two panels, the colour bar's 170 px, the titles' 60 px and the captions' 34 px.
    EXPECT_EQ(png_size(side), (std::array<int, 2>{2 * kWidth + 170, kHeight + 60 + 34})) << side;
    // f3d renders a frame's panels side by side in one strip (physics, then geometric).
    const fs::path strip = run_dir() / "pictures" / "panels" / ("strip_" + step + ".png");
    EXPECT_EQ(png_size(strip), (std::array<int, 2>{2 * kWidth, kHeight})) << strip;
    for (int k = 0; k < 2; ++k) {
      const auto rgb = pixels(strip, panel_crop(k));
      const fs::path panel = strip.string() + " panel " + std::to_string(k);
      ASSERT_EQ(rgb.size(), std::size_t(3 * kWidth * kHeight)) << panel;
      // The arm fills a good part of the frame, not all of it.
      EXPECT_GT(foreground(rgb), kWidth * kHeight / 5) << panel;
      EXPECT_LT(foreground(rgb), kWidth * kHeight) << panel;
    }
  }
  // At the first picture the stroke has only begun; at step 60 both wounds are open and the
  // wound bed shows through them.
  const auto p30 =
      pixels(run_dir() / "pictures" / "panels" / ("strip_" + stem(first_) + ".png"), panel_crop(0));
  const auto p60 = pixels(run_dir() / "pictures/panels/strip_000060.png", panel_crop(0));
  const auto g60 = pixels(run_dir() / "pictures/panels/strip_000060.png", panel_crop(1));
  EXPECT_LT(wound_bed(p30), 20);
  EXPECT_GT(wound_bed(p60), 100);
  EXPECT_GT(wound_bed(g60), 50);
  // Physics and geometric differ, and where they differ is the wound: near the centre.
  ASSERT_EQ(p60.size(), g60.size());
  int differ_centre = 0, differ_edge = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const std::size_t i = 3 * std::size_t(y * kWidth + x);
      const int d = std::abs(p60[i] - g60[i]) + std::abs(p60[i + 1] - g60[i + 1]) +
                    std::abs(p60[i + 2] - g60[i + 2]);
      const bool centre = std::abs(y - kHeight / 2) < kHeight / 6;
      if (d > 60) ++(centre ? differ_centre : differ_edge);
    }
  EXPECT_GT(differ_centre, 100);
  EXPECT_GT(differ_centre, differ_edge);
}

TEST_F(SceneRender, PictureHoldsTheStripAndAColourBar) {
  ASSERT_EQ(rc_, 0);
  const int width = 2 * kWidth + 170, height = kHeight + 60 + 34;
  const auto picture = pixels(run_dir() / "pictures/step_000060.png");
  const auto strip = pixels(run_dir() / "pictures/panels/strip_000060.png");
  ASSERT_EQ(picture.size(), std::size_t(3 * width * height));
  ASSERT_EQ(strip.size(), std::size_t(3 * 2 * kWidth * kHeight));
  // The strip is pasted as it is, 60 px down (the titles above it).
  int differ = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < 2 * kWidth; ++x)
      for (int c = 0; c < 3; ++c)
        differ += picture[std::size_t(3 * ((y + 60) * width + x) + c)] !=
                  strip[std::size_t(3 * (y * 2 * kWidth + x) + c)];
  EXPECT_EQ(differ, 0);
  // The colour bar (22 px wide, 20 px right of the panels, from 10 % to 80 % of the panel
  // height): the stretch scale's ends, orange at the top and blue at the bottom.
  const auto at = [&](int x, int y) {
    const std::size_t i = std::size_t(3 * (y * width + x));
    return std::array<int, 3>{picture[i], picture[i + 1], picture[i + 2]};
  };
  const int bar_x = 2 * kWidth + 31;
  const auto top = at(bar_x, 60 + int(0.10 * kHeight) + 3);
  const auto bottom = at(bar_x, 60 + int(0.80 * kHeight) - 3);
  EXPECT_GT(top[0], 200) << "top of the bar";  // orange (0.95, 0.55, 0.05)
  EXPECT_LT(top[2], 80) << "top of the bar";
  EXPECT_LT(bottom[0], 80) << "bottom of the bar";  // blue (0.15, 0.30, 0.80)
  EXPECT_GT(bottom[2], 170) << "bottom of the bar";
  // The title and the panel names are drawn: dark pixels in the top margin.
  int ink = 0;
  for (int y = 0; y < 60; ++y)
    for (int x = 0; x < 2 * kWidth; ++x) ink += at(x, y)[0] < 100;
  EXPECT_GT(ink, 100);
}

// The scale bar is the length of its pixels at the camera's target: a panel's height spans
// 2 d tan(a / 2) there (the camera of summary.json, through which the silhouettes below are
// checked). It is the longest 1, 2 or 5 x 10^k that fits 130 px, drawn below the colour bar;
// each panel's caption (its largest gap) is drawn below it.
TEST_F(SceneRender, PictureHasAScaleBarAtTheWoundAndEachPanelsLargestGap) {
  ASSERT_EQ(rc_, 0);
  const Json s = Json::parse(read_text(run_dir() / "summary.json"), nullptr, false);
  const Json& c = s["render"]["camera"];
  double d2 = 0;
  for (int i = 0; i < 3; ++i)
    d2 += std::pow(c["position"][i].get<double>() - c["target"][i].get<double>(), 2);
  const double mpp =
      2 * std::sqrt(d2) * std::tan(0.5 * c["view_angle"].get<double>() * M_PI / 180) / kHeight;
  const Json& bar = s["render"]["scale_bar"];
  EXPECT_NEAR(bar["metres_per_pixel_at_target"].get<double>(), mpp, 1e-9 * mpp);
  const double length = bar["length_m"];
  const int px = bar["pixels"];
  EXPECT_EQ(px, int(std::lround(length / mpp)));
  EXPECT_LE(px, 130);
  const double decade = std::pow(10.0, std::floor(std::log10(length) + 1e-9));
  const double mantissa = length / decade;
  EXPECT_TRUE(std::abs(mantissa - 1) < 1e-9 || std::abs(mantissa - 2) < 1e-9 ||
              std::abs(mantissa - 5) < 1e-9)
      << length;
  const double next = mantissa < 1.5 ? 2 : mantissa < 3 ? 5 : 10;  // the next longer bar
  EXPECT_GT(next * decade / mpp, 130.0);                           // does not fit
  // In the picture: a black bar of that many pixels, 10 px below the panels, right of them.
  const int width = 2 * kWidth + 170;
  const auto picture = pixels(run_dir() / "pictures/step_000060.png");
  ASSERT_EQ(picture.size(), std::size_t(3 * width * (kHeight + 60 + 34)));
  const auto dark = [&](int x, int y) {
    const std::size_t i = std::size_t(3 * (y * width + x));
    return picture[i] < 80 && picture[i + 1] < 80 && picture[i + 2] < 80;
  };
  int run = 0;
  for (int x = 2 * kWidth; x < width; ++x) run += dark(x, 60 + kHeight + 10);
  EXPECT_NEAR(run, px + 1, 2);
  // The captions: ink below each panel.
  for (int panel = 0; panel < 2; ++panel) {
    int ink = 0;
    for (int y = 60 + kHeight; y < 60 + kHeight + 34; ++y)
      for (int x = panel * kWidth; x < (panel + 1) * kWidth; ++x) ink += dark(x, y);
    EXPECT_GT(ink, 50) << "panel " << panel;
  }
}

// The silhouette IoU of panel k of `render` (a strip, or one panel's render) against an
// independent f3d render of frames/NAME_000060.ply (no colours) through summary.json's camera,
// over columns [x0, x1).
double silhouette_iou(const fs::path& dir, const char* name, const fs::path& render,
                      const std::string& crop, int x0, int x1) {
  const Json s = Json::parse(read_text(dir / "summary.json"), nullptr, false);
  const Json& c = s["render"]["camera"];
  const auto csv = [](const Json& v) {
    return std::to_string(v[0].get<double>()) + "," + std::to_string(v[1].get<double>()) + "," +
           std::to_string(v[2].get<double>());
  };
  const fs::path png = dir / (std::string("alone_") + name + ".png");
  const std::string cmd = "xvfb-run -a f3d --dry-run --quiet " +
                          (dir / "frames" / (std::string(name) + "_000060.ply")).string() +
                          " --output " + png.string() + " --resolution " + std::to_string(kWidth) +
                          "," + std::to_string(kHeight) + " --bg-color 1,1,1 --camera-position " +
                          csv(c["position"]) + " --camera-focal-point " + csv(c["target"]) +
                          " --camera-view-up " + csv(c["up"]) + " --camera-view-angle " +
                          std::to_string(c["view_angle"].get<double>()) + " > /dev/null 2>&1";
  if (std::system(cmd.c_str()) != 0) return -1;
  const auto alone = pixels(png), panel = pixels(render, crop);
  if (alone.size() != panel.size() || alone.empty()) return -1;
  int both = 0, either = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = x0; x < x1; ++x) {
      const std::size_t i = 3 * std::size_t(y * kWidth + x);
      const bool a = alone[i] + alone[i + 1] + alone[i + 2] < 720,
                 b = panel[i] + panel[i + 1] + panel[i + 2] < 720;
      both += a && b, either += a || b;
    }
  return double(both) / std::max(either, 1);
}

// By default f3d renders a frame's panels in one strip, through a telephoto of the panel camera
// (strip_camera): the same framing at the target, less perspective. Around the wound (the
// panel's middle third) a panel's silhouette is then close to the panel camera's (measured
// 0.88: the limb's far sides, 5 cm behind the target, are not narrowed by perspective); each
// panel sits in its own column (a wrong offset or a neighbour reaching in would spoil it).
TEST_F(SceneRender, StripPanelsMatchThePanelCameraAroundTheWound) {
  ASSERT_EQ(rc_, 0);
  const char* names[] = {"physics", "geometric"};
  for (int k = 0; k < 2; ++k) {
    const double iou =
        silhouette_iou(run_dir(), names[k], run_dir() / "pictures/panels/strip_000060.png",
                       panel_crop(k), kWidth / 3, 2 * kWidth / 3);
    std::printf("strip panel %s: silhouette IoU %.4f against the panel camera\n", names[k], iou);
    EXPECT_GT(iou, 0.8) << names[k];
  }
}

// With render.perspective every panel is its own render through the panel camera: the same
// silhouette as the independent render over the whole panel.
TEST(SceneRenderPerspective, EachPanelIsSeenThroughThePanelCamera) {
  const fs::path out =
      fs::temp_directory_path() / ("conform_scene_render_persp_" + std::to_string(::getpid()));
  ASSERT_EQ(run_conform("--set render.width=" + std::to_string(kWidth) +
                            " --set render.height=" + std::to_string(kHeight) +
                            " --set render.perspective=true --set outputs.plots=false",
                        out),
            0);
  for (const char* name : {"physics", "geometric"}) {
    const fs::path render = out / "pictures" / "panels" / (std::string(name) + "_000060.png");
    EXPECT_EQ(png_size(render), (std::array<int, 2>{kWidth, kHeight})) << render;
    const double iou = silhouette_iou(out, name, render, "", 0, kWidth);
    std::printf("panel %s: silhouette IoU %.4f against the panel camera\n", name, iou);
    EXPECT_GT(iou, 0.97) << name;
  }
  fs::remove_all(out);
  fs::remove(out.string() + ".log");
}

TEST_F(SceneRender, VideoIsAGif) {
  ASSERT_EQ(rc_, 0);
  EXPECT_EQ(read_text(run_dir() / "run.gif").substr(0, 6), "GIF89a");
}

TEST_F(SceneRender, GlbRoundTripsThroughAssimpFrameByFrame) {
  ASSERT_EQ(rc_, 0);
  Assimp::Importer glb;
  const aiScene* s = glb.ReadFile((run_dir() / "run.glb").string(), 0);
  ASSERT_NE(s, nullptr) << glb.GetErrorString();
  // Frames: physics at 0, 30, 60 and geometric at 30, 60, as the PLY frames.
  const std::vector<std::string> frames{"physics_000000", "physics_000030", "physics_000060",
                                        "geometric_000030", "geometric_000060"};
  ASSERT_EQ(s->mNumMeshes, frames.size());
  ASSERT_EQ(s->mNumAnimations, 1u);
  EXPECT_EQ(s->mAnimations[0]->mNumChannels, frames.size());
  std::vector<unsigned> vertices;
  for (const auto& name : frames) {
    // Each frame is a node of its name holding one mesh.
    const aiNode* node = s->mRootNode->FindNode(name.c_str());
    ASSERT_NE(node, nullptr) << name;
    ASSERT_EQ(node->mNumMeshes, 1u) << name;
    const aiMesh* m = s->mMeshes[node->mMeshes[0]];
    EXPECT_TRUE(m->HasNormals());
    EXPECT_TRUE(m->HasTextureCoords(0));
    EXPECT_TRUE(m->HasVertexColors(0));
    Assimp::Importer ply;
    const aiScene* f = ply.ReadFile((run_dir() / "frames" / (name + ".ply")).string(), 0);
    ASSERT_NE(f, nullptr) << name << ": " << ply.GetErrorString();
    EXPECT_EQ(m->mNumVertices, f->mMeshes[0]->mNumVertices) << name;
    // Vertex by vertex the PLY's position (float in the glb).
    double worst = 0;
    for (unsigned v = 0; v < m->mNumVertices; ++v)
      worst = std::max(worst, double((m->mVertices[v] - f->mMeshes[0]->mVertices[v]).Length()));
    EXPECT_LT(worst, 1e-6) << name;
    EXPECT_EQ(m->mNumFaces, f->mMeshes[0]->mNumFaces) << name;
    vertices.push_back(m->mNumVertices);
  }
  // The frames are of different meshes: the tear added vertices.
  EXPECT_LT(vertices[0], vertices[2]);
}

TEST_F(SceneRender, F3dOpensTheGlb) {
  ASSERT_EQ(rc_, 0);
  const fs::path png = run_dir() / "glb.png";
  const std::string cmd = "xvfb-run -a f3d --dry-run --quiet " + (run_dir() / "run.glb").string() +
                          " --output " + png.string() +
                          " --resolution 160,120 --camera-azimuth-angle 90 > /dev/null 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  const auto rgb = pixels(png);
  ASSERT_EQ(rgb.size(), std::size_t(3 * 160 * 120));
  // f3d's default background is dark grey (0.2): count what is not.
  int lit = 0;
  for (std::size_t i = 0; i + 2 < rgb.size(); i += 3) lit += std::abs(rgb[i] - 51) > 20;
  EXPECT_GT(lit, 160 * 120 / 50);
}

TEST(SceneRenderOff, NoRenderWritesNoPicturesAndNoGlb) {
  const fs::path out =
      fs::temp_directory_path() / ("conform_scene_render_off_" + std::to_string(::getpid()));
  ASSERT_EQ(run_conform("--no-render --set outputs.plots=false", out), 0);
  EXPECT_FALSE(fs::exists(out / "pictures"));
  EXPECT_FALSE(fs::exists(out / "run.glb"));
  EXPECT_TRUE(fs::exists(out / "frames" / "physics_000060.ply"));
}

// Without a display conform starts its own Xvfb when the run begins (virtual_display.hpp), and
// with the run's first frame the f3d that will render its last one (f3d_render.hpp), which then
// waits for its surface. A run killed meanwhile must leave neither behind.
TEST(SceneRenderDisplay, AKilledRunLeavesNoXvfbNorF3dBehind) {
  const fs::path out =
      fs::temp_directory_path() / ("conform_scene_render_kill_" + std::to_string(::getpid()));
  fs::remove_all(out);
  const fs::path conform = fs::path(CONFORM_BINARY_DIR) / "scenes" / "conform";
  const std::string cmd = "env -u DISPLAY " + conform.string() +
                          " run tear-opening --steps 100000 --set outputs.plots=false --out " +
                          out.string() + " > /dev/null 2>&1 & echo $!";
  FILE* f = popen(cmd.c_str(), "r");
  ASSERT_NE(f, nullptr);
  int run = 0;
  ASSERT_EQ(std::fscanf(f, "%d", &run), 1);
  pclose(f);
  const auto first_line = [](const std::string& c) {
    FILE* p = popen(c.c_str(), "r");
    char buf[64] = {0};
    if (p && !std::fgets(buf, sizeof buf, p)) buf[0] = 0;
    if (p) pclose(p);
    return std::string(buf);
  };
  // Its children, once started.
  const auto child = [&](const char* name) {
    int pid = 0;
    for (int i = 0; i < 200 && pid == 0; ++i) {
      pid = std::atoi(first_line("pgrep -P " + std::to_string(run) + " -x " + name).c_str());
      if (pid == 0) usleep(50000);
    }
    return pid;
  };
  const int xvfb = child("Xvfb"), f3d = child("f3d");
  ::kill(run, SIGKILL);
  ASSERT_GT(xvfb, 0) << "the run started no Xvfb";
  ASSERT_GT(f3d, 0) << "the run started no f3d for its last frame";
  // Gone (or a zombie waiting for its new parent to reap it) within 5 s.
  const auto alive = [&](int pid) {
    const std::string stat = read_text("/proc/" + std::to_string(pid) + "/stat");
    const auto close = stat.rfind(')');
    return close != std::string::npos && close + 2 < stat.size() && stat[close + 2] != 'Z';
  };
  for (int i = 0; i < 100 && (alive(xvfb) || alive(f3d)); ++i) usleep(50000);
  EXPECT_FALSE(alive(xvfb)) << "Xvfb " << xvfb << " outlived its run";
  EXPECT_FALSE(alive(f3d)) << "f3d " << f3d << " outlived its run";
  // The killed run's staging folder and lock file (output_folder.hpp).
  const std::string mine = "." + out.filename().string() + ".";
  for (const auto& e : fs::directory_iterator(out.parent_path()))
    if (e.path().filename().string().rfind(mine, 0) == 0) fs::remove_all(e.path());
}

// The f3d started early for the last frame may die before its surface comes (here an f3d on
// PATH that fails whenever it is given the early render's FIFO, and is the real f3d otherwise):
// the frame is then rendered anew, and the run says so.
TEST(SceneRenderEarly, AnEarlyF3dThatDiesIsReplaced) {
  const fs::path out =
      fs::temp_directory_path() / ("conform_scene_render_early_" + std::to_string(::getpid()));
  const fs::path bin = out.string() + ".bin";
  fs::create_directories(bin);
  {
    std::ofstream f3d(bin / "f3d");
    f3d << "#!/bin/sh\nfor a in \"$@\"; do case \"$a\" in */last_0.ply) exit 3;; esac; "
           "done\nexec /usr/bin/f3d \"$@\"\n";
  }
  fs::permissions(bin / "f3d", fs::perms::owner_all);
  ASSERT_EQ(run_conform("--set render.width=" + std::to_string(kWidth) + " --set render.height=" +
                            std::to_string(kHeight) + " --set outputs.plots=false",
                        out, "env PATH=" + bin.string() + ":$PATH"),
            0);
  const Json s = Json::parse(read_text(out / "summary.json"), nullptr, false);
  ASSERT_TRUE(s.is_object());
  const Json& r = s["render"];
  ASSERT_EQ(r["pictures"].size(), 1u) << r.dump(1);
  EXPECT_EQ(png_size(out / "pictures/panels/strip_000060.png"),
            (std::array<int, 2>{2 * kWidth, kHeight}));
  EXPECT_GT(foreground(pixels(out / "pictures/panels/strip_000060.png", panel_crop(0))),
            kWidth * kHeight / 5);
  EXPECT_EQ(r["timings"]["f3d_started_early"], 0);
  ASSERT_TRUE(r.contains("notes"));
  EXPECT_NE(r["notes"][0].get<std::string>().find("rendered anew"), std::string::npos);
  EXPECT_TRUE(r["warnings"].empty()) << r.dump(1);
  fs::remove_all(out);
  fs::remove_all(bin);
  fs::remove(out.string() + ".log");
}

// An f3d that exits without its picture (as f3d under Xvfb now and then does on a loaded
// machine) is run once more: here every f3d fails its first try at each picture (the early one
// after it read its surface), and the run still succeeds with all its pictures, noting each.
TEST(SceneRenderEarly, AFailedRenderIsRenderedAgainOnce) {
  const fs::path out =
      fs::temp_directory_path() / ("conform_scene_render_retry_" + std::to_string(::getpid()));
  const fs::path bin = out.string() + ".bin";
  fs::create_directories(bin);
  {
    std::ofstream f3d(bin / "f3d");
    f3d << "#!/bin/sh\nprev=\nfor a in \"$@\"; do [ \"$prev\" = --output ] && o=$a; prev=$a; "
           "done\nm=\""
        << bin.string()
        << "/tried_$(basename \"$o\")\"\n"
           "if [ ! -e \"$m\" ]; then touch \"$m\"; for a in \"$@\"; do [ -p \"$a\" ] && cat "
           "\"$a\" > /dev/null; done; exit 3; fi\n"
           "exec /usr/bin/f3d \"$@\"\n";
  }
  fs::permissions(bin / "f3d", fs::perms::owner_all);
  ASSERT_EQ(run_conform("--set render.width=" + std::to_string(kWidth) +
                            " --set render.height=" + std::to_string(kHeight) +
                            " --set render.pictures=2 --set outputs.plots=false",
                        out, "env PATH=" + bin.string() + ":$PATH"),
            0)
      << read_text(out.string() + ".log");
  const Json s = Json::parse(read_text(out / "summary.json"), nullptr, false);
  ASSERT_TRUE(s.is_object());
  const Json& r = s["render"];
  EXPECT_EQ(r["pictures"].size(), 2u) << r.dump(1);
  EXPECT_TRUE(r["failures"].empty()) << r.dump(1);
  for (const auto& picture : r["pictures"]) {
    // pictures/step_STEP.png's strip is pictures/panels/strip_STEP.png.
    std::string png = picture.get<std::string>();
    png.replace(png.find("step_"), 5, "panels/strip_");
    EXPECT_GT(foreground(pixels(out / png, panel_crop(0))), kWidth * kHeight / 5) << png;
  }
  std::size_t again = 0;
  for (const auto& note : r.value("notes", Json::array()))
    again += note.get<std::string>().find("rendered again") != std::string::npos;
  EXPECT_EQ(again, 2u) << r.dump(1);
  EXPECT_NE(r["notes"][0].get<std::string>().find("started early"), std::string::npos) << r.dump(1);
  fs::remove_all(out);
  fs::remove_all(bin);
  fs::remove(out.string() + ".log");
}

TEST(SceneRenderOff, MissingF3dIsAWarningNotAFailure) {
  const fs::path out =
      fs::temp_directory_path() / ("conform_scene_render_nof3d_" + std::to_string(::getpid()));
  // A PATH with nothing on it: no f3d (nor gnuplot); the shell is called by its full path.
  ASSERT_EQ(run_conform("--set outputs.plots=false", out, "env PATH=/nonexistent"), 0);
  const std::string log = read_text(out.string() + ".log");
  EXPECT_NE(log.find("warning: f3d is not installed"), std::string::npos) << log;
  const Json s = Json::parse(read_text(out / "summary.json"), nullptr, false);
  ASSERT_TRUE(s.is_object());
  EXPECT_TRUE(s["render"]["pictures"].empty());
  EXPECT_TRUE(fs::exists(out / "run.glb"));  // assimp needs no tool
}

}  // namespace
