// The character scene's step on Debian's rigged models as imported (brought to metres, Y up,
// welded, playing their first animation): the membrane skin against Bullet's links, each
// model in the same run. Counters: real_time (simulated seconds per wall second; above 1 is
// faster than real time) and, after the run, the ratio of the membrane's frame to the links'.
#include <benchmark/benchmark.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <string>

#include "conform/io/import.hpp"
#include "conform/io/weld_model.hpp"
#include "kinds/model_frame.hpp"
#include "kinds/soft_scene.hpp"
#include "ratio_reporter.hpp"

using namespace conform;

namespace {

const char* const kModels[] = {"FBX/huesitos.fbx",
                               "FBX/animation_with_skeleton.fbx",
                               "X/BCN_Epileptic.X",
                               "X/Testwuson.X",
                               "X/anim_test.x",
                               "SMD/WusonSMD.smd",
                               "glTF2/simple_skin/simple_skin.gltf"};

// The scene's skin (kinematic weight, pull toward the skinned targets), membrane or links.
bullet::Material character_material(bool membrane) {
  bullet::Material m;
  m.model = membrane ? bullet::MaterialModel::membrane : bullet::MaterialModel::bullet_links;
  m.kinematic_weight = 0.95;
  m.link_stiffness = 0.02;
  m.target_stiffness = 2000;
  m.target_damping = 20;
  m.damping = 0.01;
  return m;
}

struct Character {
  io::SkinnedModel model;
  std::unique_ptr<scenes::SoftWorld> world;
  bullet::SkinnedSoftBody* body = nullptr;
  Character(const std::string& file, bool membrane) : model(io::load_model(file)) {
    scenes::to_scene_frame(model, {scenes::file_units(model, file).units_per_metre, "y"});
    io::weld_model(model, {});
    scenes::CommonSettings c;
    c.substeps = 2;
    world = std::make_unique<scenes::SoftWorld>(c);
    body = &world->plugin->add_skinned_body(model, character_material(membrane));
    if (!model.animations.empty()) body->play(model.animations.front(), skin::Blend::log, false);
    body->snap_to_pose();
  }
};

void BM_CharacterFrame(benchmark::State& state) {
  const std::string file = std::string("/usr/share/assimp/models/") + kModels[state.range(0)];
  if (!std::filesystem::exists(file)) return state.SkipWithError("no assimp-testmodels");
  Character ch(file, state.range(1) == 1);
  double wall = 0, newton = 0, cg = 0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    ch.world->step();
    wall += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    newton += ch.body->last_solve().newton_iterations;
    cg += ch.body->last_solve().cg_iterations;
  }
  // The membrane's Newton and conjugate-gradient iterations per substep (its last one).
  state.counters["newton"] = newton / double(state.iterations());
  state.counters["cg"] = cg / double(state.iterations());
  // Simulated time over wall time: above 1 is faster than real time.
  state.counters["real_time"] =
      double(state.iterations()) * ch.world->dt * ch.world->substeps / wall;
  state.counters["vertices"] = double(ch.body->vertex_count());
  state.SetLabel(std::string(kModels[state.range(0)]) + (state.range(1) ? " membrane" : " links"));
}
BENCHMARK(BM_CharacterFrame)
    ->ArgsProduct({{0, 1, 2, 3, 4, 5, 6}, {1, 0}})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(30)
    ->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  for (int m = 0; m < 7; ++m)
    conform::bench::add_ratio(
        "BM_CharacterFrame/" + std::to_string(m) + "/1/iterations:30/real_time",
        "BM_CharacterFrame/" + std::to_string(m) + "/0/iterations:30/real_time", kModels[m], true);
  return conform::bench::run_with_ratios(argc, argv);
}
