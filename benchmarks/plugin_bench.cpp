// The Bullet plugin: one physics step of the skinned arm (default resolution) with CGA
// skinning against the same soft body without skinning; the time to apply a cut, a tear step
// and a drill to a live arm; and steps per second of a tear that opens.
#include <BulletSoftBody/btSoftBody.h>
#include <benchmark/benchmark.h>

#include <algorithm>
#include <memory>
#include <string>

#include "../tests/plugin/plugin_world.hpp"
#include "conform/bullet/plugin.hpp"
#include "conform/membrane/solver.hpp"
#include "conform/mesh/primitives.hpp"
#include "conform/skin/procedural_arm.hpp"
#include "ratio_reporter.hpp"

using namespace conform;
using conform::test::SoftWorld;

namespace {

const skin::Arm& the_arm() {
  static const skin::Arm arm = skin::make_arm(1);
  return arm;
}

struct LiveArm {
  SoftWorld w;
  bullet::Plugin plugin{w.world};
  bullet::SkinnedSoftBody* body;
  explicit LiveArm(int warmup = 10, double pretension = 0.05) {
    const auto& arm = the_arm();
    body = &plugin.add_skinned_body(
        arm.mesh, arm.skeleton,
        {.model = bullet::MaterialModel::bullet_links, .pretension = pretension});
    skin::PoseTrack track;
    track.set_key(0, skin::Pose::rest(arm.skeleton));
    track.set_key(1, conform::test::bent_arm_pose(arm.skeleton, 0.7, 1.2));
    track.set_key(2, skin::Pose::rest(arm.skeleton));
    body->set_keyframes(track);
    w.step(warmup);
  }
};

// Where an edit's time went (ApplyStats::seconds, wall clock), averaged over the iterations,
// in ms: the plugin's own share (sync of the simulated positions + the mirror into Bullet, by
// phase) and the mesh side (computing the change and applying it to the mesh, in core).
struct Phases {
  bullet::ApplyStats::Seconds sum;
  int n = 0;
  void add(const bullet::ApplyStats& stats) {
    const auto& s = stats.seconds;
    sum.sync += s.sync, sum.mesh += s.mesh, sum.vertices += s.vertices, sum.faces += s.faces;
    sum.pieces += s.pieces, sum.split += s.split, sum.insert += s.insert;
    ++n;
    last = stats;
  }
  bullet::ApplyStats last;
  void report(benchmark::State& state) const {
    const double k = n ? 1e3 / n : 0;
    state.counters["mesh_ms"] = k * sum.mesh;
    state.counters["plugin_ms"] = k * (sum.sync + sum.mirror());
    state.counters["sync_ms"] = k * sum.sync;
    state.counters["vert_ms"] = k * sum.vertices;
    state.counters["faces_ms"] = k * sum.faces;
    state.counters["pieces_ms"] = k * sum.pieces;
    state.counters["split_ms"] = k * sum.split;
    state.counters["insert_ms"] = k * sum.insert;
    state.counters["+faces"] = last.added_faces;
    state.counters["-faces"] = last.removed_faces;
    state.counters["+nodes"] = last.new_nodes;
    state.counters["searched"] = last.searched_vertices;
  }
};

void BM_StepSkinned(benchmark::State& state) {
  LiveArm a(10, double(state.range(0)) / 100);
  for (auto _ : state) a.w.step();
  state.counters["nodes"] = a.body->vertex_count();
}
BENCHMARK(BM_StepSkinned)->Arg(5)->Arg(0)->Unit(benchmark::kMillisecond)->MinTime(1.0);

// The same pieces (nodes, links, faces, masses, kinematic nodes with inverse mass 0) built by
// SkinnedSoftBody but never driven: no action, no skinning, no rest-length re-application.
void BM_StepUnskinned(benchmark::State& state) {
  const double pretension = double(state.range(0)) / 100;
  SoftWorld w;
  const auto& arm = the_arm();
  bullet::WorldLink link;
  link.info = &w.world.getWorldInfo();
  link.add = [&](btSoftBody* b, int group, int mask) { w.world.addSoftBody(b, group, mask); };
  link.remove = [&](btSoftBody* b) { w.world.removeSoftBody(b); };
  bullet::SkinnedSoftBody body(
      link, arm.mesh, arm.skeleton,
      {.model = bullet::MaterialModel::bullet_links, .pretension = pretension});
  w.step(10);
  for (auto _ : state) w.step();
  state.counters["nodes"] = body.vertex_count();
}
BENCHMARK(BM_StepUnskinned)->Arg(5)->Arg(0)->Unit(benchmark::kMillisecond)->MinTime(1.0);

// The skinned arm held in its rest pose: the same action (skinning, driving, rest lengths)
// but nodes that do not move, so Bullet's own work is that of the unskinned baseline.
void BM_StepSkinnedStill(benchmark::State& state) {
  LiveArm a(10, double(state.range(0)) / 100);
  a.body->set_pose(skin::Pose::rest(the_arm().skeleton));
  a.w.step(10);
  for (auto _ : state) a.w.step();
}
BENCHMARK(BM_StepSkinnedStill)->Arg(5)->Arg(0)->Unit(benchmark::kMillisecond)->MinTime(1.0);

// The plugin's whole per-substep action (pose, skinning, driving the nodes, rest lengths),
// without Bullet's step.
void BM_ActionOnly(benchmark::State& state) {
  LiveArm a;
  double t = a.plugin.time();
  for (auto _ : state) a.body->update(1.0 / 60, t += 1.0 / 60);
}
BENCHMARK(BM_ActionOnly)->Unit(benchmark::kMicrosecond);

// The per-substep finiteness check (non_finite_state.hpp): one pass over every node's position
// and velocity, once a substep (before the drive). Its share of a step: this against
// BM_StepSkinned.
void BM_NonFiniteCheck(benchmark::State& state) {
  LiveArm a;
  for (auto _ : state) benchmark::DoNotOptimize(a.body->first_non_finite_node());
  state.counters["nodes"] = a.body->vertex_count();
}
BENCHMARK(BM_NonFiniteCheck)->Unit(benchmark::kMicrosecond);

// Skinning alone (pose, per-bone kernels, eq 17 vertex loop) for one substep.
void BM_SkinTargets(benchmark::State& state) {
  LiveArm a(1);
  double t = 0;
  for (auto _ : state) a.body->skin_targets(t += 1e-3);
}
BENCHMARK(BM_SkinTargets)->Unit(benchmark::kMicrosecond);

// A plane across the forearm of a live arm: compute the cut on the simulated positions, apply
// it to the mesh and to Bullet (the arm splits into two bodies).
void BM_CutLiveArm(benchmark::State& state) {
  Phases phases;
  int moved = 0;
  for (auto _ : state) {
    state.PauseTiming();
    auto a = std::make_unique<LiveArm>();
    state.ResumeTiming();
    a->body->cut(cga::Plane<double>::from_normal_point({0.1, 0, 1}, {0, 0, 0.42}));
    state.PauseTiming();
    phases.add(a->body->last_apply());
    moved = a->body->last_apply().moved_nodes;
    a.reset();
    state.ResumeTiming();
  }
  phases.report(state);
  state.counters["moved"] = moved;
}
BENCHMARK(BM_CutLiveArm)->Unit(benchmark::kMillisecond)->Iterations(30)->Repetitions(5);

// Only the application of an already computed cut (mesh + Bullet mirror).
void BM_ApplyCutLiveArm(benchmark::State& state) {
  Phases phases;
  for (auto _ : state) {
    state.PauseTiming();
    auto a = std::make_unique<LiveArm>();
    a->body->sync_mesh();
    const auto result = mesh::compute_cut(
        a->body->mesh(), cga::Plane<double>::from_normal_point({0.1, 0, 1}, {0, 0, 0.42}));
    state.ResumeTiming();
    a->body->apply(result.change);
    state.PauseTiming();
    phases.add(a->body->last_apply());
    a.reset();
    state.ResumeTiming();
  }
  phases.report(state);
}
BENCHMARK(BM_ApplyCutLiveArm)->Unit(benchmark::kMillisecond)->Iterations(30)->Repetitions(5);

// One tear step (a blade sample advancing an open tear on the upper arm), compute + apply.
void BM_TearStepLiveArm(benchmark::State& state) {
  Phases phases;
  for (auto _ : state) {
    state.PauseTiming();
    auto a = std::make_unique<LiveArm>();
    a->body->begin_tear();
    for (int i = 0; i < 6; ++i) {
      const double z = 0.08 + 0.006 * i;
      a->body->tear_advance({double(i), {0, 0, z}, {0.15, 0, z}});
    }
    a->w.step();
    state.ResumeTiming();
    a->body->tear_advance({6.0, {0, 0, 0.116}, {0.15, 0, 0.116}});
    state.PauseTiming();
    phases.add(a->body->last_apply());
    a.reset();
    state.ResumeTiming();
  }
  phases.report(state);
}
BENCHMARK(BM_TearStepLiveArm)->Unit(benchmark::kMillisecond)->Iterations(30)->Repetitions(5);

// A 1 cm drill through both walls of the upper arm, compute + apply.
void BM_DrillLiveArm(benchmark::State& state) {
  Phases phases;
  int detached = 0;
  for (auto _ : state) {
    state.PauseTiming();
    auto a = std::make_unique<LiveArm>(1);
    const Eigen::Vector3d c(0, 0, 0.15);
    state.ResumeTiming();
    a->body->drill({c + Eigen::Vector3d(0, 0.2, 0), c - Eigen::Vector3d(0, 0.2, 0), 0.01});
    state.PauseTiming();
    phases.add(a->body->last_apply());
    detached = a->body->detached_count();
    a.reset();
    state.ResumeTiming();
  }
  phases.report(state);
  state.counters["detached"] = detached;
}
BENCHMARK(BM_DrillLiveArm)->Unit(benchmark::kMillisecond)->Iterations(30)->Repetitions(5);

// The first physics step after an edit (a cut that splits the arm, or a drill): Bullet does
// no whole-body reset (the plugin wrote the constants of what changed), so it should cost
// about a normal step of the same bodies (BM_StepAfterEdit/…/settled, a later step).
void BM_StepAfterEdit(benchmark::State& state) {
  const bool cut = state.range(0) == 1, settled = state.range(1) == 1;
  for (auto _ : state) {
    state.PauseTiming();
    auto a = std::make_unique<LiveArm>();
    if (cut)
      a->body->cut(cga::Plane<double>::from_normal_point({0.1, 0, 1}, {0, 0, 0.42}));
    else
      a->body->drill({Eigen::Vector3d(0, 0.2, 0.15), Eigen::Vector3d(0, -0.2, 0.15), 0.01});
    if (settled) a->w.step(3);
    state.ResumeTiming();
    a->w.step();
    state.PauseTiming();
    a.reset();
    state.ResumeTiming();
  }
}
BENCHMARK(BM_StepAfterEdit)
    ->ArgsProduct({{0, 1}, {0, 1}})
    ->ArgNames({"cut", "settled"})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(30)
    ->Repetitions(5);

// Steps per second of a torn, pre-tensioned 40×40 patch while it opens.
void BM_OpeningTearStep(benchmark::State& state) {
  SoftWorld w;
  bullet::Plugin plugin(w.world);
  const mesh::SkinnedMesh m = test::one_bone_sheet(40, 40, 1.0, 1.0);
  auto& body = plugin.add_skinned_body(m, test::one_bone_skeleton(),
                                       {.damping = 0.05,
                                        .pretension = 0.1,
                                        .target_stiffness = 0,
                                        .target_damping = 0,
                                        .kinematic_weight = 2,
                                        .position_iterations = 10});
  std::vector<std::int32_t> border;
  for (std::int32_t v = 0; v < m.vertex_count(); ++v)
    if (std::abs(m.rest(0, v)) > 0.5 - 1e-9 || std::abs(m.rest(1, v)) > 0.5 - 1e-9)
      border.push_back(v);
  body.set_pinned(border);
  body.begin_tear();
  for (int i = 0; i < 60; ++i) {
    const double x = -0.25 + 0.5 * i / 59;
    body.tear_advance({double(i), {x, 0.0123, -0.1}, {x, 0.0123, 0.1}});
  }
  for (auto _ : state) w.step();
  state.SetItemsProcessed(state.iterations());
  state.counters["nodes"] = body.vertex_count();
}
BENCHMARK(BM_OpeningTearStep)->Unit(benchmark::kMillisecond)->MinTime(1.0);

// The default material against two baselines in the same run: Bullet's pre-tensioned links
// (the tear-opening scene's link settings, the default before the membrane) and the membrane
// at its previous solver settings (1 Pa, block-Jacobi CG); and the membrane with its Newton
// systems solved in place rather than packed (packed_systems off: the same results). The arm of
// `resolution` (1: 2.6k vertices, 2: 10k, 3: 23k).
enum Variant { kLinks = 0, kMembrane = 1, kMembranePrevious = 2, kMembraneUnpacked = 3 };

// The torn arm of tear-opening (its scene defaults: one 1/60 s substep a frame for the
// membrane; two substeps of 1/120 s for the links). BM_StepTornArm: the stroke is done and the
// elbow flexes slowly, so every frame solves; BM_StillTornArm: the stroke is done and the arm
// holds still, so every frame's membrane step starts in balance (most of tear-opening's
// frames: the cost of a step that needs no Newton iteration); BM_TearArm: the clock runs over
// the stroke itself, an edit before every frame.
struct TornArm {
  SoftWorld w;
  bullet::Plugin plugin{w.world};
  bullet::SkinnedSoftBody* body = nullptr;
  bool membrane;
  int next = 0;                         // the next of the stroke's 40 samples
  long newton = 0, cg = 0, frames = 0;  // summed over the frames, for the means

  /// toughness > 0: the tear grows by itself (Material::growth) at that G_c, J/m^2.
  TornArm(int variant, int resolution, int threads, bool flexing = true, double toughness = 0)
      : membrane(variant != kLinks) {
    const skin::Arm arm = skin::make_arm(resolution);
    bullet::Material material;
    material.solver.threads = threads;
    if (toughness > 0) {
      material.skin.toughness = toughness;
      material.growth.enabled = true;
      material.growth.domain_radius = 0.015;  // tear-opening's tear.growth_radius
    }
    if (variant == kMembranePrevious) {
      material.solver.relative_tolerance = 1.0 / material.skin.stress_scale();
      material.solver.preconditioner = membrane::Preconditioner::block_jacobi;
    }
    if (variant == kMembraneUnpacked) {
      material.solver.packed_systems = false;
    }
    if (variant == kLinks)
      material = {.model = bullet::MaterialModel::bullet_links,
                  .damping = 0.02,
                  .pretension = 0.2,
                  .target_stiffness = 4000,
                  .target_damping = 40,
                  .kinematic_weight = 2};
    body = &plugin.add_skinned_body(arm.mesh, arm.skeleton, material);
    skin::PoseTrack track;
    track.set_key(0, skin::Pose::rest(arm.skeleton));
    if (flexing) track.set_key(60, conform::test::bent_arm_pose(arm.skeleton, 0.0, 1.5));
    body->set_keyframes(track);
    body->begin_tear();
  }
  void tear(int samples) {
    for (int end = std::min(40, next + samples); next < end; ++next) {
      const double z = 0.3712 + 0.12 * next / 39;
      body->tear_advance({double(next), {0.09, 0.0023, z}, {0.005, 0.0023, z}});
    }
  }
  void frame() {
    if (membrane)
      w.bullet::SoftWorld::step(1.0 / 60, 1);
    else
      w.bullet::SoftWorld::step(1.0 / 120, 2);
    newton += body->last_solve().newton_iterations;
    cg += body->last_solve().cg_iterations;
    ++frames;
  }
};

void report_solve(benchmark::State& state, const TornArm& a, double simulated_per_iteration) {
  state.counters["nodes"] = a.body->vertex_count();
  state.counters["newton"] = a.body->last_solve().newton_iterations;
  // The last frame's count alone hides how often a still arm's frames solve at all.
  state.counters["newton_mean"] = double(a.newton) / double(std::max(1L, a.frames));
  state.counters["cg_mean"] = double(a.cg) / double(std::max(1L, a.frames));
  state.counters["realtime_x"] = benchmark::Counter(
      double(state.iterations()) * simulated_per_iteration, benchmark::Counter::kIsRate);
}

void BM_StepTornArm(benchmark::State& state) {
  TornArm a(int(state.range(0)), int(state.range(1)), int(state.range(2)));
  a.tear(40);
  for (int i = 0; i < 30; ++i) a.frame();
  a.newton = a.cg = a.frames = 0;
  for (auto _ : state) a.frame();
  report_solve(state, a, 1.0 / 60);
}
BENCHMARK(BM_StepTornArm)
    ->ArgNames({"variant", "res", "threads"})
    ->Args({kMembrane, 1, 1})
    ->Args({kMembrane, 1, 2})
    ->Args({kMembranePrevious, 1, 1})
    ->Args({kLinks, 1, 1})
    ->Args({kMembrane, 2, 1})
    ->Args({kMembrane, 2, 2})
    ->Args({kMembranePrevious, 2, 1})
    ->Args({kMembraneUnpacked, 2, 1})
    ->Args({kLinks, 2, 1})
    ->Args({kMembrane, 3, 1})
    ->Args({kMembrane, 3, 2})
    ->Args({kMembraneUnpacked, 3, 1})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0);

void BM_StillTornArm(benchmark::State& state) {
  TornArm a(int(state.range(0)), int(state.range(1)), int(state.range(2)), false);
  a.tear(40);
  for (int i = 0; i < 60; ++i) a.frame();  // the wound opens and settles
  a.newton = a.cg = a.frames = 0;
  for (auto _ : state) a.frame();
  report_solve(state, a, 1.0 / 60);
}
BENCHMARK(BM_StillTornArm)
    ->ArgNames({"variant", "res", "threads"})
    ->Args({kMembrane, 2, 1})
    ->Args({kMembrane, 2, 2})
    ->Args({kMembraneUnpacked, 2, 1})
    ->Args({kMembrane, 3, 1})
    ->Args({kMembrane, 3, 2})
    ->Args({kMembraneUnpacked, 3, 1})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0);

// The stroke: 40 samples over 30 frames (0.5 s), an edit before every frame.
void BM_TearArm(benchmark::State& state) {
  std::unique_ptr<TornArm> a;
  for (auto _ : state) {
    state.PauseTiming();
    a = std::make_unique<TornArm>(int(state.range(0)), int(state.range(1)), int(state.range(2)));
    a->frame();
    state.ResumeTiming();
    for (int f = 0; f < 30; ++f) {
      a->tear(f % 3 == 2 ? 2 : 1);  // 20 x 1 + 10 x 2 = 40 samples in 30 frames
      a->frame();
    }
  }
  report_solve(state, *a, 0.5);
}
BENCHMARK(BM_TearArm)
    ->ArgNames({"variant", "res", "threads"})
    ->Args({kMembrane, 1, 1})
    ->Args({kMembrane, 1, 2})
    ->Args({kMembranePrevious, 1, 1})
    ->Args({kLinks, 1, 1})
    ->Args({kMembrane, 2, 1})
    ->Args({kMembranePrevious, 2, 1})
    ->Args({kMembraneUnpacked, 2, 1})
    ->Args({kLinks, 2, 1})
    ->Args({kMembrane, 3, 1})
    ->Args({kMembrane, 3, 2})
    ->Args({kMembraneUnpacked, 3, 1})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0);

// One growth step of the torn arm's tear at resolution 1 (its G at both tips, the decision, the
// crack extension and its mirror into Bullet: SkinnedSoftBody::grow_tear), against one scripted
// tear step (a blade sample, computed and mirrored) on the same arm mid-stroke. The stroke is
// done and settled; toughness 300 J/m^2 (G is about 560 there) makes both tips grow, 1e5 none.
void BM_GrowthStepTornArm(benchmark::State& state) {
  const double toughness = state.range(0) ? 300.0 : 1e5;
  double grown = 0;
  for (auto _ : state) {
    state.PauseTiming();
    auto a = std::make_unique<TornArm>(kMembrane, 1, 1, false, toughness);
    a->tear(40);
    for (int i = 0; i < 20; ++i) a->frame();
    state.ResumeTiming();
    grown += a->body->grow_tear().grown;
    state.PauseTiming();
    a.reset();
    state.ResumeTiming();
  }
  state.counters["grown_mm"] = 1e3 * grown / double(state.iterations());
}
BENCHMARK(BM_GrowthStepTornArm)
    ->ArgNames({"grows"})
    ->Arg(1)
    ->Arg(0)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(10)
    ->Repetitions(3);

void BM_ScriptedTearStepTornArm(benchmark::State& state) {
  for (auto _ : state) {
    state.PauseTiming();
    auto a = std::make_unique<TornArm>(kMembrane, 1, 1, false);
    a->tear(20);
    for (int i = 0; i < 20; ++i) a->frame();
    state.ResumeTiming();
    a->tear(1);
    state.PauseTiming();
    a.reset();
    state.ResumeTiming();
  }
}
BENCHMARK(BM_ScriptedTearStepTornArm)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(10)
    ->Repetitions(3);

}  // namespace

int main(int argc, char** argv) {
  for (const char* grows : {"1", "0"})
    conform::bench::add_ratio(
        std::string("BM_GrowthStepTornArm/grows:") + grows + "/iterations:10/repeats:3",
        "BM_ScriptedTearStepTornArm/iterations:10/repeats:3",
        std::string("a growth step ") + (grows[0] == '1' ? "(both tips grow)" : "(judged only)") +
            " / a scripted tear step, torn arm, resolution 1");
  for (const std::string bench : {"BM_StepTornArm", "BM_TearArm", "BM_StillTornArm"})
    for (const std::string r : {"1", "2", "3"}) {
      const auto name = [&](int variant, const char* threads) {
        return bench + "/variant:" + std::to_string(variant) + "/res:" + r + "/threads:" + threads +
               "/min_time:2.000";
      };
      const std::string what = (bench == "BM_TearArm"        ? "the stroke"
                                : bench == "BM_StillTornArm" ? "still torn arm"
                                                             : "torn arm") +
                               std::string(", resolution ") + r;
      conform::bench::add_ratio(name(kMembrane, "1"), name(kMembranePrevious, "1"),
                                "membrane / its previous settings (1 Pa, Jacobi), " + what);
      conform::bench::add_ratio(name(kMembrane, "1"), name(kMembraneUnpacked, "1"),
                                "membrane / unpacked Newton systems (same results), " + what);
      conform::bench::add_ratio(name(kMembrane, "1"), name(kLinks, "1"),
                                "membrane / Bullet links (the default before), " + what);
      conform::bench::add_ratio(name(kMembrane, "2"), name(kMembrane, "1"),
                                "membrane, 2 threads / 1 thread [wall], " + what, true);
    }
  for (const char* s : {"5", "0"}) {
    const std::string base = std::string("BM_StepUnskinned/") + s + "/min_time:1.000";
    conform::bench::add_ratio(std::string("BM_StepSkinned/") + s + "/min_time:1.000", base,
                              std::string("animated skinned / unskinned, s = 0.0") + s);
    conform::bench::add_ratio(std::string("BM_StepSkinnedStill/") + s + "/min_time:1.000", base,
                              std::string("still skinned / unskinned, s = 0.0") + s);
  }
  for (const char* e : {"0", "1"})
    conform::bench::add_ratio(
        std::string("BM_StepAfterEdit/cut:") + e + "/settled:0/iterations:30/repeats:5",
        std::string("BM_StepAfterEdit/cut:") + e + "/settled:1/iterations:30/repeats:5",
        std::string("first step after ") + (e[0] == '1' ? "a cut" : "a drill") + " / a later step");
  return conform::bench::run_with_ratios(argc, argv);
}
