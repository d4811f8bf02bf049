#include <algorithm>
// The membrane element against finite differences of its own energy, and its invariants.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "conform/membrane/detail/cst_kernel.hpp"
#include "conform/membrane/model.hpp"

namespace conform::membrane {
namespace {

struct Triangle {
  Eigen::Matrix3Xd rest{3, 3}, x{3, 3};
  std::vector<mesh::Face> faces{{0, 1, 2}};
};

Triangle random_triangle(std::mt19937& rng, double stretch) {
  std::uniform_real_distribution<double> u(-1, 1);
  Triangle t;
  t.rest << 0, 0.01, 0.002, 0, 0.001, 0.012, 0, 0.0005, -0.001;
  for (int i = 0; i < 9; ++i) t.rest(i % 3, i / 3) += 0.002 * u(rng);
  t.x = t.rest * (1 + stretch);
  for (int i = 0; i < 9; ++i) t.x(i % 3, i / 3) += 0.001 * u(rng);
  return t;
}

SkinMaterial anisotropic() {
  SkinMaterial m;
  m.prestress = {60e3, 20e3};
  m.prestress_axis = Eigen::Vector3d(0.3, 1, 0.2);
  return m;
}

TEST(MembraneKernel, GradientIsTheDerivativeOfTheEnergy) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 20; ++trial) {
    Triangle t = random_triangle(rng, 0.1 * (trial % 3) - 0.05);
    Model model;
    model.build(t.rest, t.faces, anisotropic());
    Eigen::Matrix3Xd g(3, 3);
    model.gradient(t.x, g);
    const double h = 1e-8;
    for (int i = 0; i < 9; ++i) {
      Eigen::Matrix3Xd plus = t.x, minus = t.x;
      plus(i % 3, i / 3) += h;
      minus(i % 3, i / 3) -= h;
      const double fd = (model.energy(plus) - model.energy(minus)) / (2 * h);
      EXPECT_NEAR(g(i % 3, i / 3), fd, 1e-6 * g.cwiseAbs().maxCoeff() + 1e-9) << trial << " " << i;
    }
  }
}

TEST(MembraneKernel, HessianActionIsTheDerivativeOfTheGradientInTension) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 20; ++trial) {
    Triangle t = random_triangle(rng, 0.08);  // stretched: S is positive, the Hessian is exact
    Model model;
    model.build(t.rest, t.faces, anisotropic());
    const detail::ElementRest& e = model.elements()[0];
    const detail::ElementState s = detail::element_state(
        e, t.x.col(0), t.x.col(1), t.x.col(2), model.lambda(), model.mu(), model.wrinkling());
    ASSERT_TRUE((s.s_pos - (s.f.transpose() * s.f).inverse() * s.f.transpose() * s.p).norm() <
                1e-6 * s.s_pos.norm());
    Eigen::Matrix3Xd d = Eigen::Matrix3Xd::Random(3, 3);
    Eigen::Vector3d o0, o1, o2;
    detail::hessian_apply(e, s, model.lambda(), model.mu(), d.col(0), d.col(1), d.col(2), o0, o1,
                          o2);
    const double h = 1e-7;
    Eigen::Matrix3Xd gp(3, 3), gm(3, 3);
    model.gradient(t.x + h * d, gp);
    model.gradient(t.x - h * d, gm);
    const Eigen::Matrix3Xd fd = (gp - gm) / (2 * h);
    Eigen::Matrix3Xd out(3, 3);
    out << o0, o1, o2;
    EXPECT_LT((out - fd).norm(), 1e-5 * fd.norm()) << trial;
    // Its blocks: column `axis` of K_ab is the action on a unit displacement of node b.
    for (int b = 0; b < 3; ++b)
      for (int axis = 0; axis < 3; ++axis) {
        Eigen::Matrix3Xd unit = Eigen::Matrix3Xd::Zero(3, 3);
        unit(axis, b) = 1;
        detail::hessian_apply(e, s, model.lambda(), model.mu(), unit.col(0), unit.col(1),
                              unit.col(2), o0, o1, o2);
        for (int a = 0; a < 3; ++a) {
          const Eigen::Matrix3d k = detail::hessian_block(e, s, model.lambda(), model.mu(), a, b);
          const Eigen::Vector3d column = a == 0 ? o0 : a == 1 ? o1 : o2;
          EXPECT_LT((k.col(axis) - column).norm(), 1e-9 * k.norm() + 1e-12);
          Eigen::Matrix3d upper[6];  // the solver's assembly: the six distinct blocks at once
          detail::hessian_upper_blocks(e, s, model.lambda(), model.mu(), upper);
          const int lo = std::min(a, b), hi = std::max(a, b);
          const int slot = lo == 0 ? hi : lo == 1 ? 2 + hi : 5;  // (0,0) (0,1) (0,2) (1,1) ...
          const Eigen::Matrix3d block = a <= b ? upper[slot] : upper[slot].transpose();
          EXPECT_LT((block - k).norm(), 1e-12 * k.norm() + 1e-15);
        }
      }
  }
}

TEST(MembraneKernel, RigidMotionChangesNothingAndRestCarriesOnlyThePrestress) {
  std::mt19937 rng(3);
  Triangle t = random_triangle(rng, 0.05);
  Model model;
  model.build(t.rest, t.faces, anisotropic());
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Matrix3Xd moved = (r * t.x).colwise() + Eigen::Vector3d(0.3, -1, 2);
  EXPECT_NEAR(model.energy(moved), model.energy(t.x), 1e-12 * std::abs(model.energy(t.x)) + 1e-18);
  // At rest: no strain energy; the forces are the pre-stress's, which sum to zero.
  EXPECT_LT(std::abs(model.energy(t.rest)), 1e-15);
  Eigen::Matrix3Xd g(3, 3);
  model.gradient(t.rest, g);
  EXPECT_LT(g.rowwise().sum().norm(), 1e-12 * g.norm());
  // Without pre-stress the rest state is force-free.
  SkinMaterial free = anisotropic();
  free.prestress = {0, 0};
  model.build(t.rest, t.faces, free);
  model.gradient(t.rest, g);
  EXPECT_LT(g.norm(), 1e-9);
}

TEST(MembraneKernel, NodalAreasAreAThirdOfTheFacesAndDegenerateFacesCarryNothing) {
  Eigen::Matrix3Xd rest(3, 5);
  rest << 0, 1, 0, 1, 2, 0, 0, 1, 1, 0, 0, 0, 0, 0, 0;
  const std::vector<mesh::Face> faces{{0, 1, 2}, {1, 3, 2}, {0, 1, 4}};  // the last is flat
  Model model;
  model.build(rest, faces, SkinMaterial{});
  EXPECT_EQ(model.element_count(), 2);
  EXPECT_EQ(model.degenerate_faces(), 1);
  EXPECT_NEAR(model.node_area(0), 0.5 / 3, 1e-15);
  EXPECT_NEAR(model.node_area(1), 1.0 / 3, 1e-15);
  EXPECT_EQ(model.node_area(4), 0.0);
  EXPECT_NEAR(model.node_mass(1), SkinMaterial{}.areal_density / 3, 1e-15);
}

TEST(MembraneKernel, MaterialValidationNamesTheField) {
  SkinMaterial m;
  m.poisson_ratio = 0.5;
  EXPECT_THROW(
      {
        try {
          m.validate();
        } catch (const std::invalid_argument& e) {
          EXPECT_NE(std::string(e.what()).find("poisson_ratio = 0.5"), std::string::npos)
              << e.what();
          throw;
        }
      },
      std::invalid_argument);
  m = SkinMaterial{};
  m.attachment_stiffness = -1;
  EXPECT_THROW(m.validate(), std::invalid_argument);
  m = SkinMaterial{};
  m.youngs_modulus = std::nan("");
  EXPECT_THROW(m.validate(), std::invalid_argument);
  EXPECT_NO_THROW(SkinMaterial{}.validate());
  EXPECT_NEAR(equibiaxial_prestress(SkinMaterial{}, 0.1), 0.42e6 * 0.1 / 0.52, 1e-6);
}

}  // namespace
}  // namespace conform::membrane
