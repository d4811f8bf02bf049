// `conform ik --target X Y Z [--swivel PHI] [--upper D1] [--fore D2] [--json]`: one closed-form
// arm IK solve (conform/ik/arm_ik.hpp). Prints Qs and Qe ([w, x, y, z], unit, v' = q v q*),
// the elbow point, the status and the forward-kinematics wrist error |FK wrist − target|
// (for a clamped target: its distance from the reachable shell).
#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <utility>
#include <vector>

#include "base/finite_json.hpp"
#include "cli/commands.hpp"
#include "conform/ik/arm_ik.hpp"

namespace conform::cli {

namespace {

// Arm segment lengths, m: below a micrometre (denormals passed as "positive") or above a
// thousand kilometres the solve loses all precision or overflows.
constexpr double kMinLength = 1e-6, kMaxLength = 1e6;

struct IkOptions {
  std::vector<double> target;
  double swivel = 0;
  double upper = 0.30;  // the procedural arm's upper arm [m]
  double fore = 0.25;   // and forearm [m]
  bool json = false;
};

int run_ik(const IkOptions& o) {
  if (o.target.size() != 3 || !std::isfinite(o.target[0]) || !std::isfinite(o.target[1]) ||
      !std::isfinite(o.target[2])) {
    std::cerr << "conform ik: --target needs three finite numbers X Y Z\n";
    return 2;
  }
  for (const auto& [name, length] : {std::pair{"--upper", o.upper}, std::pair{"--fore", o.fore}})
    if (!(length >= kMinLength && length <= kMaxLength)) {
      std::cerr << "conform ik: " << name << " " << length << " must be a length in [" << kMinLength
                << ", " << kMaxLength << "] m\n";
      return 2;
    }
  if (!std::isfinite(o.swivel) || std::abs(o.swivel) > ik::kMaxSwivel) {
    std::cerr << "conform ik: --swivel must be a finite angle in radians, |PHI| <= "
              << ik::kMaxSwivel << "\n";
    return 2;
  }
  ik::Arm<double> arm;
  arm.upper = o.upper;
  arm.fore = o.fore;
  const Eigen::Vector3d target(o.target[0], o.target[1], o.target[2]);
  ik::Solution<double> s = ik::solve(arm, target, o.swivel);
  if (ik::has(s.status, ik::Status::kInvalidInput)) {
    std::cerr << "conform ik: the solver rejected the input (" << ik::to_string(s.status) << ")\n";
    return 1;
  }
  // q and −q are the same rotation: print the one with w ≥ 0.
  if (s.qs.w() < 0) s.qs.coeffs() = -s.qs.coeffs();
  s.qs.normalize();
  s.qe.normalize();
  const auto fk = ik::forward_kinematics(arm, s.qs, s.qe);
  const double wrist_error = (fk.wrist - target).norm();
  const auto quat = [](const Eigen::Quaterniond& q) {
    return std::vector<double>{q.w() + 0.0, q.x() + 0.0, q.y() + 0.0, q.z() + 0.0};  // no −0
  };
  nlohmann::json j;
  j["qs"] = quat(s.qs);
  j["qe"] = quat(s.qe);
  j["elbow"] = {s.elbow.x() + 0.0, s.elbow.y() + 0.0, s.elbow.z() + 0.0};
  j["wrist"] = {fk.wrist.x(), fk.wrist.y(), fk.wrist.z()};
  j["status"] = ik::to_string(s.status);
  j["wrist_error"] = wrist_error;
  // Finite or refused, in both forms of the output.
  if (const std::string bad = scenes::first_non_finite(j); !bad.empty()) {
    std::cerr << "conform ik: the solution's " << bad << " is not finite (the lengths or the "
              << "target are too large for double precision); nothing printed\n";
    return 1;
  }
  if (o.json) {
    j.erase("wrist");
    std::cout << j.dump() << "\n";
    return 0;
  }
  const auto print = [](const char* name, const std::vector<double>& v) {
    std::cout << "  " << std::left << std::setw(12) << name << "[";
    for (std::size_t i = 0; i < v.size(); ++i) std::cout << (i ? ", " : "") << v[i];
    std::cout << "]\n";
  };
  std::cout << std::setprecision(10) << "arm: upper " << arm.upper << " m, forearm " << arm.fore
            << " m, swivel " << o.swivel << " rad\n";
  print("qs [w,x,y,z]", quat(s.qs));
  print("qe [w,x,y,z]", quat(s.qe));
  print("elbow", {s.elbow.x(), s.elbow.y(), s.elbow.z()});
  print("wrist (FK)", {fk.wrist.x(), fk.wrist.y(), fk.wrist.z()});
  std::cout << "  status      " << ik::to_string(s.status) << "\n"
            << "  wrist_error " << wrist_error << " m\n";
  return 0;
}

}  // namespace

void register_ik(CLI::App& app, Context& context) {
  auto opts = std::make_shared<IkOptions>();
  auto* cmd = app.add_subcommand(
      "ik",
      "Arm inverse kinematics (closed-form CGA, first paper): shoulder at the origin, rest "
      "arm along +z");
  cmd->add_option("--target", opts->target, "Wrist target X Y Z [m]")->expected(3)->required();
  cmd->add_option("--swivel", opts->swivel,
                  "Swivel angle PHI [rad] about the shoulder-wrist line (0: elbow towards +z)")
      ->capture_default_str();
  cmd->add_option("--upper", opts->upper, "Upper arm length D1 [m], in [1e-6, 1e6]")
      ->capture_default_str();
  cmd->add_option("--fore", opts->fore, "Forearm length D2 [m], in [1e-6, 1e6]")
      ->capture_default_str();
  cmd->add_flag("--json", opts->json, "Print one JSON object: qs, qe, elbow, status, wrist_error");
  cmd->callback([opts, &context]() { context.exit_code = run_ik(*opts); });
}

}  // namespace conform::cli
