#include <iomanip>
#include <iostream>

#include "cli/commands.hpp"
#include "conform/bullet/convert.hpp"
#include "conform/io/import.hpp"
#include "conform/version.hpp"

namespace conform::cli {
namespace {

void print_model(const io::SkinnedModel& m) {
  std::cout << "model " << m.source << "\n"
            << "  meshes: " << m.meshes.size() << " (merged in this order)\n";
  for (const auto& mi : m.meshes)
    std::cout << "    " << std::quoted(mi.name) << ": " << mi.vertex_count << " vertices, "
              << mi.face_count << " faces, "
              << (mi.bones > 0 ? std::to_string(mi.bones) + " bones" : std::string("rigid"))
              << ", node "
              << std::quoted(m.skeleton.joints[static_cast<std::size_t>(mi.joint)].name) << "\n";
  std::cout << "  vertices: " << m.mesh.vertex_count() << "\n"
            << "  faces: " << m.mesh.face_count() << "\n"
            << "  nodes: " << m.skeleton.joint_count() << "\n"
            << "  bones: " << m.skeleton.bone_count() << "\n";
  for (const auto& b : m.skeleton.bones) {
    std::cout << "    " << std::quoted(b.name);
    const auto parent = m.skeleton.joints[static_cast<std::size_t>(b.joint)].parent;
    if (parent >= 0)
      std::cout << " (parent node "
                << std::quoted(m.skeleton.joints[static_cast<std::size_t>(parent)].name) << ")";
    std::cout << "\n";
  }
  std::cout << "  largest number of influences per vertex: " << m.influences.max_per_vertex()
            << "\n"
            << "  animations: " << m.animations.size() << "\n";
  for (std::size_t i = 0; i < m.animations.size(); ++i) {
    const auto& a = m.animations[i];
    std::size_t keys = 0;
    for (const auto& c : a.channels)
      keys += c.translation.size() + c.rotation.size() + c.scale.size();
    std::cout << "    [" << i << "] " << std::quoted(a.name) << ": " << a.duration() << " s ("
              << a.duration_ticks << " ticks at " << a.ticks_per_second << " ticks/s), "
              << a.channels.size() << " channels, " << keys << " keys\n";
  }
  const Eigen::Vector3d lo = m.mesh.current.rowwise().minCoeff(),
                        hi = m.mesh.current.rowwise().maxCoeff();
  std::cout << "  bind-pose bounds: [" << lo.transpose() << "] .. [" << hi.transpose() << "]\n";
  for (const auto& w : m.warnings) std::cerr << "warning: " << m.source << ": " << w << "\n";
}

}  // namespace

void register_info(CLI::App& app, Context& context) {
  auto* cmd = app.add_subcommand(
      "info", "Print the version and features, or, given MODEL, its meshes, bones and animations");
  auto model = std::make_shared<std::string>();
  auto options = std::make_shared<io::ImportOptions>();
  options->isolate = true;  // a corrupt file must not kill or corrupt the command
  cmd->add_option("MODEL", *model, "model file (any format assimp reads) or arm[:N]");
  add_strict_weights(cmd, options->strict_weights);
  add_import_limits(cmd, options->isolation);
  cmd->callback([&context, model, options]() {
    if (model->empty()) {
      std::cout << "conform " << conform::version() << "\n"
                << "  Bullet precision: " << conform::bullet::bullet_precision() << "\n"
                << "  algebra: G(4,1) multivectors, motors, dilators, versors (conform::core)\n"
                << "  skinning: CGA eq 17 and versor blend; matrix LBS and dual-quaternion "
                   "baselines\n"
                << "  import: assimp (rigged models), procedural arm (arm[:N])\n";
      context.exit_code = 0;
      return;
    }
    try {
      print_model(io::load_model(*model, *options));
      context.exit_code = 0;
    } catch (const std::exception& e) {
      std::cerr << "conform info: " << e.what() << "\n";
      context.exit_code = 1;
    }
  });
}

}  // namespace conform::cli
