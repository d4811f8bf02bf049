// `conform cut`, `conform tear` and `conform drill`: load a model (a file or arm[:N]), pose it
// (the bind pose, or --animation A --time T), apply the operation to its current (posed,
// world-space) positions, and write every resulting piece as PLY (or OBJ) into DIR with a
// summary.json of counts and timings. A posed edit also writes the pieces at rest into DIR/rest/
// (new vertices get the same combination of rest positions as of posed ones). DIR is written
// atomically (output_folder.hpp): it holds exactly this run's files, or the earlier ones. DIR
// must not be the current folder, hold the model or the scalpel file, or be a folder of other
// files (exit 2). A stop signal while the pieces are written leaves the earlier ones (exit
// 128 + the signal).
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "base/finite_json.hpp"
#include "base/interrupt.hpp"
#include "base/output_folder.hpp"
#include "cli/commands.hpp"
#include "cli/model_pose.hpp"
#include "cli/scalpel_csv.hpp"
#include "conform/io/import.hpp"
#include "conform/io/mesh_export.hpp"
#include "conform/mesh/analysis.hpp"
#include "conform/mesh/cut.hpp"
#include "conform/mesh/drill.hpp"
#include "conform/mesh/tear.hpp"
#include "kinds/provenance.hpp"

namespace conform::cli {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

struct Common {
  std::string model;
  std::string out;
  std::string format = "ply";
  bool strict_weights = false;
  std::string animation = "0";
  double time = 0;
  bool posed = false;  // --time given
  io::IsolationLimits import_limits;
  std::vector<fs::path> inputs;  // files read besides the model (the scalpel)
};

void add_common(CLI::App* cmd, Common& c) {
  cmd->add_option("MODEL", c.model, "model file (any format assimp reads) or arm[:N]")->required();
  cmd->add_option("--out", c.out, "output directory (created if missing)")->required();
  cmd->add_option("--format", c.format, "ply (binary), ply-ascii or obj")
      ->check(CLI::IsMember({"ply", "ply-ascii", "obj"}));
  add_strict_weights(cmd, c.strict_weights);
  add_import_limits(cmd, c.import_limits);
  cmd->add_option(
      "--animation", c.animation,
      "with --time: the animation to pose the model with, by name or index (default 0)");
  cmd->add_option_function<double>(
         "--time",
         [&c](double t) {
           c.time = t;
           c.posed = true;
         },
         "edit the model posed at this time of the animation (s; default: the bind pose)")
      ->check(CLI::NonNegativeNumber);
}

// Vertices that the faces `faces` of `m` use.
std::int32_t used_vertex_count(const mesh::SkinnedMesh& m, const std::vector<std::int32_t>& faces) {
  std::vector<char> used(static_cast<std::size_t>(m.vertex_count()), 0);
  std::int32_t n = 0;
  for (auto f : faces)
    for (auto v : m.faces[static_cast<std::size_t>(f)])
      n += used[static_cast<std::size_t>(v)] ? 0 : (used[static_cast<std::size_t>(v)] = 1);
  return n;
}

// The area of `faces` at the rest positions.
double rest_area(const mesh::SkinnedMesh& m, const std::vector<std::int32_t>& faces) {
  double area = 0;
  for (auto f : faces) {
    const auto& t = m.faces[static_cast<std::size_t>(f)];
    area += 0.5 *
            (m.rest.col(t[1]) - m.rest.col(t[0])).cross(m.rest.col(t[2]) - m.rest.col(t[0])).norm();
  }
  return area;
}

// The files the command reads: --out must not replace the folder of any of them.
std::vector<fs::path> inputs(const Common& c) {
  std::vector<fs::path> all = c.inputs;
  all.emplace_back(c.model);
  return all;
}

// Loads the model; returns its mesh (current = the bind pose in world space).
mesh::SkinnedMesh load(const Common& c, nlohmann::json& summary) {
  scenes::check_output_folder(c.out, inputs(c));  // refused before the long work
  const auto t0 = Clock::now();
  summary["provenance"] = scenes::provenance(std::chrono::system_clock::now());
  io::ImportOptions options;
  options.strict_weights = c.strict_weights;
  options.isolate = true;  // a corrupt file must not kill or corrupt the command
  options.isolation = c.import_limits;
  io::SkinnedModel model = io::load_model(c.model, options);
  for (const auto& w : model.warnings)
    std::cerr << "warning: " << model.source << ": " << w << "\n";
  summary["model"] = model.source;
  summary["warnings"] = model.warnings;
  summary["input"] = {{"vertices", model.mesh.vertex_count()}, {"faces", model.mesh.face_count()}};
  if (c.posed) {
    pose_model(model, c.animation, c.time);
    summary["pose"] = {{"animation", find_animation_or_throw(model, c.animation).name},
                       {"time_s", c.time}};
  }
  summary["timing_ms"]["load"] = ms_since(t0);
  return std::move(model.mesh);
}

// Every piece of `m` into `dir`, at its current or rest positions; the pieces' list.
nlohmann::json write_piece_files(const fs::path& dir, const mesh::SkinnedMesh& m,
                                 const mesh::Pieces& pieces, io::MeshFormat format, bool rest) {
  std::vector<std::vector<std::int32_t>> faces(static_cast<std::size_t>(pieces.count));
  for (std::size_t f = 0; f < pieces.face_piece.size(); ++f)
    faces[static_cast<std::size_t>(pieces.face_piece[f])].push_back(static_cast<std::int32_t>(f));
  nlohmann::json list = nlohmann::json::array();
  for (std::int32_t p = 0; p < pieces.count; ++p) {
    char name[32];
    std::snprintf(name, sizeof name, "piece_%03d%s", p, io::mesh_format_extension(format));
    const auto& pf = faces[static_cast<std::size_t>(p)];
    scenes::check_interrupt();
    io::write_mesh(dir / name, m, {format, rest, true}, pf);
    list.push_back({{"file", name},
                    {"vertices", used_vertex_count(m, pf)},
                    {"faces", pf.size()},
                    {"area", rest ? rest_area(m, pf) : mesh::surface_area(m, pf)}});
  }
  return list;
}

// Writes every piece and summary.json (and the rest pieces of a posed edit): only these files
// are in the directory afterwards.
void write_pieces(const Common& c, const mesh::SkinnedMesh& m, nlohmann::json& summary) {
  const auto t0 = Clock::now();
  const scenes::StopOnSignals stop;
  scenes::OutputFolder folder{fs::path(c.out), inputs(c)};
  const io::MeshFormat format = io::parse_mesh_format(c.format);
  const mesh::Pieces pieces = mesh::label_pieces(m);
  const nlohmann::json list = write_piece_files(folder.staging(), m, pieces, format, false);
  if (c.posed) {
    fs::create_directories(folder.staging() / "rest");
    summary["rest_pieces"] = write_piece_files(folder.staging() / "rest", m, pieces, format, true);
  }
  std::vector<std::int32_t> all(static_cast<std::size_t>(m.face_count()));
  for (std::size_t f = 0; f < all.size(); ++f) all[f] = static_cast<std::int32_t>(f);
  const std::int32_t used = used_vertex_count(m, all);
  const mesh::MeshReport report = mesh::check_mesh(m);
  // Counts are of what the files hold: vertices no face uses (left by an edit) are not written.
  summary["output"] = {{"vertices", used},
                       {"faces", m.face_count()},
                       {"unused_vertices", m.vertex_count() - used},
                       {"pieces", pieces.count},
                       {"piece_files", list},
                       {"closed", report.closed()},
                       {"manifold", report.manifold()},
                       {"oriented", report.oriented()}};
  summary["timing_ms"]["write"] = ms_since(t0);
  scenes::require_finite(summary, "summary.json");
  std::ofstream os(folder.staging() / "summary.json");
  os << summary.dump(2) << "\n";
  os.close();
  if (!os) throw std::runtime_error("cannot write " + (fs::path(c.out) / "summary.json").string());
  scenes::check_interrupt();
  folder.commit();
}

template <class Fn>
void run(Context& context, const char* name, Fn fn) {
  try {
    fn();
    context.exit_code = 0;
  } catch (const scenes::Interrupted& stop) {
    std::cerr << "conform " << name << ": stopped by " << scenes::signal_name(stop.signal)
              << "; the earlier results are untouched\n";
    context.exit_code = stop.exit_code();
  } catch (const scenes::OutputRefused& e) {
    std::cerr << "conform " << name << ": " << e.what() << "\n";
    context.exit_code = 2;
  } catch (const std::exception& e) {
    std::cerr << "conform " << name << ": " << e.what() << "\n";
    context.exit_code = 1;
  }
}

// The largest --open: the model's bounding-box diagonal (a wider opening moves the borders
// out of the model; 1e308 wrote vertices at 5e307 and an infinite area).
void check_opening(double open, const mesh::SkinnedMesh& m) {
  const double diagonal =
      m.vertex_count() > 0
          ? (m.current.rowwise().maxCoeff() - m.current.rowwise().minCoeff()).norm()
          : 0.0;
  if (open > diagonal) {
    std::ostringstream why;
    why << "--open " << open << " is more than the model's size (its bounding-box diagonal, "
        << diagonal << ")";
    throw std::runtime_error(why.str());
  }
}

}  // namespace

namespace {

// `conform cut`: a plane through the model (Algorithm 1), the pieces written out.
void register_cut(CLI::App& app, Context& context) {
  auto common = std::make_shared<Common>();
  auto plane = std::make_shared<std::vector<double>>();
  auto cap = std::make_shared<bool>(false);
  auto sphere = std::make_shared<std::vector<double>>();
  auto seed = std::make_shared<std::vector<double>>();
  auto touching = std::make_shared<bool>(false);
  auto* cmd =
      app.add_subcommand("cut", "Cut a model by a plane (Algorithm 1) and write the pieces");
  add_common(cmd, *common);
  cmd->add_option("--plane", *plane, "unit normal and distance: NX NY NZ D (n·x = D)")
      ->expected(4)
      ->required();
  cmd->add_flag("--cap", *cap, "close every cut loop with a triangulated cap");
  auto* sphere_opt =
      cmd->add_option("--region-sphere", *sphere,
                      "cut only the sections of the plane inside this sphere: X Y Z R")
          ->expected(4);
  cmd->add_option("--region-seed", *seed, "cut only the section nearest this point: X Y Z")
      ->expected(3)
      ->excludes(sphere_opt);
  cmd->add_flag("--touching", *touching,
                "with --region-sphere: the sections that meet the sphere (default: inside it)")
      ->needs(sphere_opt);
  cmd->callback([&context, common, plane, cap, sphere, seed, touching]() {
    run(context, "cut", [&] {
      nlohmann::json summary;
      summary["command"] = "cut";
      mesh::SkinnedMesh m = load(*common, summary);
      const auto& p = *plane;
      const auto t0 = Clock::now();
      mesh::Adjacency adjacency(m);
      const double t_adj = ms_since(t0);
      const auto t1 = Clock::now();
      mesh::CutOptions options{.cap = *cap};
      const auto& sp = *sphere;
      if (!sp.empty())
        options.region = mesh::CutRegion::sphere(
            {sp[0], sp[1], sp[2]}, sp[3],
            *touching ? mesh::CutRegion::Keep::touching : mesh::CutRegion::Keep::inside);
      if (!seed->empty())
        options.region = mesh::CutRegion::seed({(*seed)[0], (*seed)[1], (*seed)[2]});
      const mesh::CutOutcome out =
          mesh::cut(m, adjacency,
                    cga::Plane<double>::from_normal_distance({p[0], p[1], p[2]}, p[3]), options);
      summary["timing_ms"]["adjacency"] = t_adj;
      summary["timing_ms"]["operation"] = ms_since(t1);
      summary["status"] = out.result.status == mesh::CutStatus::Cut ? "cut" : "missed";
      summary["crossed_edges"] = out.result.crossed_edges;
      summary["snapped_vertices"] = out.result.snapped_vertices;
      summary["new_vertices"] = out.result.change.new_vertices.size();
      if (options.region.shape != mesh::CutRegion::Shape::everywhere)
        summary["region"] = {{"sections", out.result.sections},
                             {"kept_sections", out.result.kept_sections}};
      if (*cap)
        summary["cap"] = {{"loops", out.result.loops},
                          {"capped", out.result.capped_loops},
                          {"faces_per_side", out.result.cap_faces}};
      if (!out.result.message.empty()) summary["message"] = out.result.message;
      if (out.result.status != mesh::CutStatus::Cut)
        std::cerr << "conform cut: " << out.result.message << " (no-op)\n";
      write_pieces(*common, m, summary);
    });
  });
}

// `conform tear`: a scalpel path through the model (Algorithm 2).
void register_tear(CLI::App& app, Context& context) {
  auto common = std::make_shared<Common>();
  auto scalpel = std::make_shared<std::string>();
  auto open = std::make_shared<double>(0.0);
  auto* cmd = app.add_subcommand("tear", "Tear a model along a scalpel path (Algorithm 2)");
  add_common(cmd, *common);
  cmd->add_option("--scalpel", *scalpel, "CSV with header t,ax,ay,az,bx,by,bz")->required();
  cmd->add_option("--open", *open, "move the tear's two borders apart by this much (m)")
      ->check(CLI::NonNegativeNumber);
  auto options = std::make_shared<mesh::TearOptions>();
  cmd->add_flag("--smooth-lips", options->smooth_lips,
                "place each new tip at the blade's hit and join it by edge flips, as the scenes "
                "do: smooth, evenly spaced lips (default: the paper's path along edge crossings)");
  cmd->callback([&context, common, scalpel, open, options]() {
    run(context, "tear", [&] {
      nlohmann::json summary;
      summary["command"] = "tear";
      const auto samples = scenes::read_scalpel_csv(*scalpel);
      common->inputs = {*scalpel};
      mesh::SkinnedMesh m = load(*common, summary);
      check_opening(*open, m);
      const auto t0 = Clock::now();
      mesh::Adjacency adjacency(m);
      const double t_adj = ms_since(t0);
      const auto t1 = Clock::now();
      mesh::Tear tear(m, adjacency, *options);
      for (const auto& s : samples) tear.advance(s);
      if (*open > 0) tear.open(*open);
      summary["timing_ms"]["adjacency"] = t_adj;
      summary["timing_ms"]["operation"] = ms_since(t1);
      summary["samples"] = samples.size();
      summary["smooth_lips"] = options->smooth_lips;
      summary["tear"] = {
          {"steps", tear.steps()}, {"points", tear.path_length()}, {"length", tear.length()}};
      if (!tear.message().empty()) summary["message"] = tear.message();
      if (tear.steps() == 0)
        throw std::runtime_error(
            "the scalpel never tore the surface: " +
            (tear.message().empty() ? std::string("no blade crossed it") : tear.message()));
      write_pieces(*common, m, summary);
    });
  });
}

// `conform drill`: a cylindrical hole (Algorithm 3).
void register_drill(CLI::App& app, Context& context) {
  auto common = std::make_shared<Common>();
  auto tip = std::make_shared<std::vector<double>>();
  auto base = std::make_shared<std::vector<double>>();
  auto radius = std::make_shared<double>(0.0);
  auto options = std::make_shared<mesh::DrillOptions>();
  auto* cmd = app.add_subcommand("drill", "Drill a cylindrical hole (Algorithm 3)");
  add_common(cmd, *common);
  cmd->add_option("--tip", *tip, "drill tip A: X Y Z")->expected(3)->required();
  cmd->add_option("--base", *base, "drill base B: X Y Z")->expected(3)->required();
  cmd->add_option("--radius", *radius, "drill radius (m)")->required();
  cmd->add_flag("--tube", options->tube,
                "join the entry and exit holes of a closed surface with a tube wall");
  cmd->add_option("--tube-rings", options->tube_ring_spacing,
                  "with --tube: rings of new vertices at most SPACING x the rims' mean edge "
                  "apart (0: one triangle spans the wall)")
      ->check(CLI::NonNegativeNumber);
  cmd->callback([&context, common, tip, base, radius, options]() {
    run(context, "drill", [&] {
      nlohmann::json summary;
      summary["command"] = "drill";
      mesh::SkinnedMesh m = load(*common, summary);
      const auto& a = *tip;
      const auto& b = *base;
      const auto t0 = Clock::now();
      mesh::Adjacency adjacency(m);
      const double t_adj = ms_since(t0);
      const auto t1 = Clock::now();
      if (options->tube_ring_spacing > 0 && !options->tube)
        throw std::runtime_error("--tube-rings needs --tube");
      const mesh::DrillResult r =
          mesh::drill(m, adjacency, {{a[0], a[1], a[2]}, {b[0], b[1], b[2]}, *radius}, *options);
      summary["timing_ms"]["adjacency"] = t_adj;
      summary["timing_ms"]["operation"] = ms_since(t1);
      summary["holes"] = r.holes;
      summary["rim_vertices"] = r.rim_vertices;
      summary["removed_faces"] = r.removed_area_faces;
      summary["removed_area"] = r.removed_area;
      summary["refinements"] = r.refinements;
      if (options->tube) summary["tube"] = {{"tubes", r.tubes}, {"faces", r.tube_faces}};
      if (!r.message.empty()) summary["message"] = r.message;
      if (r.holes == 0)
        throw std::runtime_error("the drill does not pierce the surface: " + r.message);
      write_pieces(*common, m, summary);
    });
  });
}

}  // namespace

void register_mesh_ops(CLI::App& app, Context& context) {
  register_cut(app, context);
  register_tear(app, context);
  register_drill(app, context);
}

}  // namespace conform::cli
