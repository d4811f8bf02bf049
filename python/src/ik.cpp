// conform.ik: the closed-form CGA arm IK, one target (solve) or many over numpy arrays
// (solve_batch: ik::BatchSolveJob), and forward kinematics, the contract both honour.
// Quaternions are (w, x, y, z) (Hamilton, v' = q v q*).
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "conform/ik/arm_ik.hpp"

namespace conform::python {
namespace {

using Arm = ik::Arm<double>;
using Quat = Eigen::Quaterniond;

Eigen::Vector4d wxyz(const Quat& q) {
  return {q.w(), q.x(), q.y(), q.z()};
}
Quat quat(const Eigen::Vector4d& q) {
  return {q[0], q[1], q[2], q[3]};
}

py::dict solve(const Eigen::Vector3d& target, double swivel, const Arm& arm) {
  const ik::Solution<double> s = ik::solve(arm, target, swivel);
  py::dict d;
  d["qs"] = wxyz(s.qs);
  d["qe"] = wxyz(s.qe);
  d["elbow"] = s.elbow;
  d["status"] = static_cast<int>(s.status);
  d["status_text"] = ik::to_string(s.status);
  return d;
}

// targets (N, 3) and swivel (N,) or a scalar. The targets are copied into the job's
// structure of arrays; the outputs are written in place (qs (N, 4) and elbow (N, 3) are
// views of (4, N) and (3, N) buffers).
py::dict solve_batch(const py::array_t<double, py::array::c_style | py::array::forcecast>& targets,
                     const py::object& swivel, const Arm& arm, int threads) {
  if (targets.ndim() != 2 || targets.shape(1) != 3)
    throw std::invalid_argument("solve_batch: targets must have shape (N, 3)");
  const py::ssize_t n = targets.shape(0);
  py::array_t<double> soa({py::ssize_t(4), n});  // x, y, z, swivel rows
  auto s = soa.mutable_unchecked<2>();
  auto t = targets.unchecked<2>();
  const auto phi = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(swivel);
  if (!phi || (phi.ndim() != 0 && (phi.ndim() != 1 || phi.shape(0) != n)))
    throw std::invalid_argument("solve_batch: swivel must be a scalar or have shape (N,)");
  for (py::ssize_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) s(k, i) = t(i, k);
    s(3, i) = phi.ndim() == 0 ? phi.data()[0] : phi.data()[i];
  }
  py::array_t<double> qs({py::ssize_t(4), n}), qe({py::ssize_t(2), n}), elbow({py::ssize_t(3), n});
  py::array_t<std::uint8_t> status(n);
  auto row = [n](py::array_t<double>& a, int r) {
    return std::span<double>(a.mutable_data(r, 0), std::size_t(n));
  };
  auto in = [n, &soa](int r) { return std::span<const double>(soa.data(r, 0), std::size_t(n)); };
  ik::BatchSolveJob<double> job;
  job.arm = arm;
  job.x = in(0), job.y = in(1), job.z = in(2), job.swivel = in(3);
  job.qs_w = row(qs, 0), job.qs_x = row(qs, 1), job.qs_y = row(qs, 2), job.qs_z = row(qs, 3);
  job.qe_w = row(qe, 0), job.qe_x = row(qe, 1);
  job.elbow_x = row(elbow, 0), job.elbow_y = row(elbow, 1), job.elbow_z = row(elbow, 2);
  job.status = std::span<std::uint8_t>(status.mutable_data(), std::size_t(n));
  job.threads = threads;
  if (const std::string problem = job.validate(); !problem.empty())
    throw std::invalid_argument("solve_batch: " + problem);
  {
    py::gil_scoped_release release;
    job.run();
  }
  py::dict d;
  d["qs"] = qs.attr("T");
  d["qe"] = qe.attr("T");
  d["elbow"] = elbow.attr("T");
  d["status"] = status;
  return d;
}

py::tuple forward(const Eigen::Vector4d& qs, const Eigen::Vector4d& qe, const Arm& arm) {
  const auto r = ik::forward_kinematics(arm, quat(qs), quat(qe));
  return py::make_tuple(Eigen::Vector3d(r.elbow), Eigen::Vector3d(r.wrist));
}

// Batched forward kinematics: qs (N, 4), qe (N, 4) or (N, 2) (w, x).
py::tuple forward_batch(const Eigen::MatrixX4d& qs, const Eigen::MatrixXd& qe, const Arm& arm) {
  if (qe.rows() != qs.rows() || (qe.cols() != 4 && qe.cols() != 2))
    throw std::invalid_argument("forward_kinematics_batch: qs (N, 4) and qe (N, 4) or (N, 2)");
  Eigen::MatrixX3d elbow(qs.rows(), 3), wrist(qs.rows(), 3);
  for (Eigen::Index i = 0; i < qs.rows(); ++i) {
    const Quat e = qe.cols() == 4 ? Quat(qe(i, 0), qe(i, 1), qe(i, 2), qe(i, 3))
                                  : Quat(qe(i, 0), qe(i, 1), 0, 0);
    const auto r = ik::forward_kinematics(arm, quat(qs.row(i).transpose()), e);
    elbow.row(i) = r.elbow.transpose(), wrist.row(i) = r.wrist.transpose();
  }
  return py::make_tuple(elbow, wrist);
}

void bind_arm(py::module_& m) {
  py::class_<Arm>(m, "Arm", "A two-segment arm: upper (d1) and fore (d2) in m, elbow range in rad.")
      .def(py::init([](double upper, double fore, double elbow_min, double elbow_max) {
             Arm a;
             a.upper = upper, a.fore = fore;
             a.limits.elbow_min = elbow_min, a.limits.elbow_max = elbow_max;
             return a;
           }),
           py::arg("upper") = 0.30, py::arg("fore") = 0.25, py::arg("elbow_min") = 0.0,
           py::arg("elbow_max") = std::numbers::pi)
      .def_readwrite("upper", &Arm::upper)
      .def_readwrite("fore", &Arm::fore)
      .def_property(
          "elbow_min", [](const Arm& a) { return a.limits.elbow_min; },
          [](Arm& a, double v) { a.limits.elbow_min = v; })
      .def_property(
          "elbow_max", [](const Arm& a) { return a.limits.elbow_max; },
          [](Arm& a, double v) { a.limits.elbow_max = v; })
      .def("valid", &Arm::valid);
}

}  // namespace

void bind_ik(py::module_& parent) {
  py::module_ m = parent.def_submodule("ik", "Closed-form CGA inverse kinematics of the arm.");
  bind_arm(m);
  m.def("solve", &solve, py::arg("target"), py::arg("swivel") = 0.0, py::arg("arm") = Arm{},
        "One wrist target and swivel angle (rad): {qs, qe, elbow, status, status_text}.");
  m.def("solve_batch", &solve_batch, py::arg("targets"), py::arg("swivel") = 0.0,
        py::arg("arm") = Arm{}, py::arg("threads") = 1,
        "Targets (N, 3), swivel (N,) or scalar: {qs (N, 4), qe (N, 2) as (w, x), elbow (N, 3), "
        "status (N,) uint8}, by the batch job (SIMD; OpenMP threads, 0: OpenMP's default).");
  m.def("forward_kinematics", &forward, py::arg("qs"), py::arg("qe"), py::arg("arm") = Arm{},
        "(elbow, wrist) of the shoulder and elbow quaternions.");
  m.def("forward_kinematics_batch", &forward_batch, py::arg("qs"), py::arg("qe"),
        py::arg("arm") = Arm{}, "(elbow (N, 3), wrist (N, 3)) of qs (N, 4) and qe (N, 4 or 2).");
  m.def("status_text", [](int s) { return ik::to_string(static_cast<ik::Status>(s)); });
}

}  // namespace conform::python
