// Bad model files give an ImportError naming the file and the problem, never a crash; the
// `conform info` command exits non-zero on them.
#include <gtest/gtest.h>

#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <new>

#include "conform/io/crash_guard.hpp"
#include "conform/io/import.hpp"

namespace {

using conform::io::ImportError;

const std::string kBroken = std::string(CONFORM_TEST_DATA) + "/broken/";

struct Broken {
  const char* file;
  const char* problem;  // a phrase the message must contain
  bool strict = false;  // refused with ImportOptions::strict_weights (normalized by default)
};

class BrokenFile : public testing::TestWithParam<Broken> {};

TEST_P(BrokenFile, ThrowsImportErrorNamingFileAndProblem) {
  const Broken b = GetParam();
  const std::string path = kBroken + b.file;
  ASSERT_TRUE(std::filesystem::exists(path)) << path;
  conform::io::ImportOptions options;
  options.strict_weights = b.strict;
  try {
    conform::io::import_model(path, options);
    FAIL() << "imported " << path;
  } catch (const ImportError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(path, 0), 0u) << what;  // starts with the file name
    EXPECT_EQ(e.file(), path);
    EXPECT_NE(what.find(b.problem), std::string::npos) << what;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Files, BrokenFile,
    testing::Values(Broken{"huesitos_truncated.fbx", "cannot be read"},
                    Broken{"simple_skin_truncated.gltf", "cannot be read"},
                    Broken{"anim_test_truncated.x", "end of file"},
                    Broken{"notes_renamed.fbx", "cannot be read"},
                    Broken{"notes_renamed.dae", "cannot be read"},
                    Broken{"simple_skin_nan_key.gltf", "NaN or infinite rotation key 3"},
                    Broken{"simple_skin_bad_weights.gltf", "sum to 0.700000, not 1", true},
                    Broken{"simple_skin_bad_joint.gltf", "sum to 0.250000, not 1", true},
                    Broken{"mesh.unknownformat", "unsupported format"}),
    [](const auto& info) {
      std::string n = info.param.file;
      for (auto& c : n)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
      return n;
    });

// Weights off 1 are normalized by default (issue 13: engines normalize on import), with one
// warning that gives the range of the sums; strict_weights refuses them (above).
TEST(IoBroken, WeightsOffOneAreNormalizedWithOneWarningByDefault) {
  for (const char* file : {"simple_skin_bad_weights.gltf", "simple_skin_bad_joint.gltf"}) {
    const auto m = conform::io::import_model(kBroken + file);
    int warnings = 0;
    for (const auto& w : m.warnings) warnings += w.find("do not sum to 1") != std::string::npos;
    EXPECT_EQ(warnings, 1) << file;
    for (Eigen::Index v = 0; v < m.mesh.vertex_count(); ++v)
      EXPECT_NEAR(m.mesh.weights.col(v).sum(), 1.0, 1e-12) << file << " vertex " << v;
  }
}

// The guard itself, on work whose fate is known: a crash in the child is reported by its signal
// and leaves the caller running; work that returns or throws is not a crash.
TEST(IoBroken, CrashGuardReportsTheChildsSignal) {
  EXPECT_EQ(conform::io::crash_in_child([] { std::raise(SIGSEGV); }), strsignal(SIGSEGV));
  EXPECT_EQ(conform::io::crash_in_child([] { std::abort(); }), strsignal(SIGABRT));
  EXPECT_EQ(conform::io::crash_in_child([] {}), "");
  EXPECT_EQ(conform::io::crash_in_child([] { throw std::bad_alloc(); }), "");
  // The child works on a copy: nothing it writes reaches the caller.
  int value = 1;
  conform::io::crash_in_child([&] { value = 2; });
  EXPECT_EQ(value, 1);
}

// Files on which assimp 5.2 has undefined behaviour (a joint index out of range in the Collada
// loader, a vertex index out of range in the X loader). What happens depends on the machine's
// memory layout: a segfault or heap-corruption abort here, a std::bad_alloc caught by assimp on
// another machine. With the crash guard either way ends in an ImportError naming the file, and
// the caller survives.
TEST(IoBroken, CrashGuardTurnsAssimpCrashesIntoErrors) {
  conform::io::ImportOptions o;
  o.crash_guard = true;
  for (const char* f : {"box_joint_out_of_range.dae", "triangle_vertex_out_of_range.x"}) {
    const std::string path = kBroken + f;
    try {
      conform::io::import_model(path, o);
      ADD_FAILURE() << f;
    } catch (const ImportError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(path, 0), 0u) << what;
      EXPECT_TRUE(what.find("assimp crashed reading it") != std::string::npos ||
                  what.find("cannot be read") != std::string::npos)
          << what;
    }
  }
  // The guard lets good files through, with the same result.
  const std::string good = std::string(CONFORM_ASSIMP_MODELS) + "/Collada/box_nested_animation.dae";
  const auto a = conform::io::import_model(good, o), b = conform::io::import_model(good);
  EXPECT_EQ(a.mesh.rest, b.mesh.rest);
  EXPECT_EQ(a.skeleton.bone_count(), b.skeleton.bone_count());
}

TEST(IoBroken, MissingFileAndDirectory) {
  try {
    conform::io::import_model(kBroken + "does_not_exist.fbx");
    FAIL();
  } catch (const ImportError& e) {
    EXPECT_NE(std::string(e.what()).find("does_not_exist.fbx: no such file"), std::string::npos);
  }
  try {
    conform::io::load_model(kBroken);
    FAIL();
  } catch (const ImportError& e) {
    EXPECT_NE(std::string(e.what()).find("directory"), std::string::npos);
  }
}

TEST(IoBroken, OriginalsOfTheBrokenCopiesImport) {
  // The broken files are broken by their edits, not because the originals are.
  const std::string models = CONFORM_ASSIMP_MODELS;
  EXPECT_NO_THROW(conform::io::import_model(models + "/FBX/huesitos.fbx"));
  EXPECT_NO_THROW(conform::io::import_model(models + "/glTF2/simple_skin/simple_skin.gltf"));
  EXPECT_NO_THROW(conform::io::import_model(models + "/X/anim_test.x"));
}

// The command: non-zero exit and the message on stderr. Needs the `conform` binary of this
// build tree.
TEST(IoBroken, InfoCommandExitsNonZero) {
  const std::string conform = std::string(CONFORM_BINARY_DIR) + "/scenes/conform";
  if (!std::filesystem::exists(conform)) GTEST_SKIP() << "conform not built";
  const std::string out = ::testing::TempDir() + "io_broken_info.txt";
  for (const char* f :
       {"notes_renamed.fbx", "simple_skin_nan_key.gltf", "box_joint_out_of_range.dae"}) {
    const std::string cmd = conform + " info " + kBroken + f + " > /dev/null 2> " + out;
    const int rc = std::system(cmd.c_str());
    EXPECT_NE(rc, 0) << f;
    std::ifstream in(out);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find(f), std::string::npos) << text;
  }
  EXPECT_EQ(std::system((conform + " info arm > /dev/null").c_str()), 0);
}

}  // namespace
