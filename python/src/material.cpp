// Material (the plugin's), SkinMaterial (the membrane's skin) and SolverSettings (the membrane's
// solve), with their enums. Fields are copied in and out (a Body keeps its own Material).
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "conform/bullet/skinned_soft_body.hpp"

namespace conform::python {
namespace {

using bullet::Material;
using membrane::SkinMaterial;
using membrane::SolverSettings;

void bind_skin(py::module_& m) {
  py::class_<SkinMaterial> skin(
      m, "SkinMaterial", "The skin membrane's material in SI units (membrane/skin_material.hpp).");
  py::enum_<SkinMaterial::Law>(skin, "Law")
      .value("stvk", SkinMaterial::Law::stvk)
      .value("neo_hookean", SkinMaterial::Law::neo_hookean)
      .value("fibre_reinforced", SkinMaterial::Law::fibre_reinforced);
  py::enum_<SkinMaterial::DirectionField>(skin, "DirectionField")
      .value("axis", SkinMaterial::DirectionField::axis)
      .value("along_bones", SkinMaterial::DirectionField::along_bones)
      .value("around_bones", SkinMaterial::DirectionField::around_bones);
  skin.def(py::init<>())
      .def_readwrite("law", &SkinMaterial::law)
      .def_readwrite("youngs_modulus", &SkinMaterial::youngs_modulus, "Pa")
      .def_readwrite("fibre_stiffness", &SkinMaterial::fibre_stiffness, "Pa")
      .def_readwrite("fibre_nonlinearity", &SkinMaterial::fibre_nonlinearity)
      .def_readwrite("poisson_ratio", &SkinMaterial::poisson_ratio)
      .def_readwrite("thickness", &SkinMaterial::thickness, "m")
      .def_readwrite("areal_density", &SkinMaterial::areal_density, "kg/m^2")
      .def_readwrite("prestress", &SkinMaterial::prestress, "the two principal pre-stresses, Pa")
      .def_readwrite("prestress_axis", &SkinMaterial::prestress_axis)
      .def_readwrite("prestress_field", &SkinMaterial::prestress_field)
      .def_readwrite("attachment_stiffness", &SkinMaterial::attachment_stiffness, "Pa/m")
      .def_readwrite("attachment_normal_stiffness", &SkinMaterial::attachment_normal_stiffness,
                     "Pa/m")
      .def_readwrite("attachment_damping", &SkinMaterial::attachment_damping, "Pa s/m")
      .def_readwrite("toughness", &SkinMaterial::toughness,
                     "G_c, J/m^2: energy per unit of new crack area through the thickness")
      .def_readwrite("wrinkling", &SkinMaterial::wrinkling);
}

void bind_solver(py::module_& m) {
  py::enum_<membrane::Preconditioner>(m, "Preconditioner")
      .value("block_jacobi", membrane::Preconditioner::block_jacobi)
      .value("symmetric_gauss_seidel", membrane::Preconditioner::symmetric_gauss_seidel);
  py::class_<SolverSettings>(m, "SolverSettings", "The membrane's solve of each substep.")
      .def(py::init<>())
      .def_readwrite("relative_tolerance", &SolverSettings::relative_tolerance)
      .def_readwrite("max_newton_iterations", &SolverSettings::max_newton_iterations)
      .def_readwrite("max_cg_iterations", &SolverSettings::max_cg_iterations)
      .def_readwrite("cg_relative_tolerance", &SolverSettings::cg_relative_tolerance)
      .def_readwrite("preconditioner", &SolverSettings::preconditioner)
      .def_readwrite("local_fraction", &SolverSettings::local_fraction)
      .def_readwrite("local_reach", &SolverSettings::local_reach)
      .def_readwrite("threads", &SolverSettings::threads);
  py::class_<membrane::SolveReport>(m, "SolveReport", "The membrane's solve of the last substep.")
      .def_readonly("initial_residual", &membrane::SolveReport::initial_residual, "Pa")
      .def_readonly("residual", &membrane::SolveReport::residual, "Pa")
      .def_readonly("relative_residual", &membrane::SolveReport::relative_residual)
      .def_readonly("newton_iterations", &membrane::SolveReport::newton_iterations)
      .def_readonly("cg_iterations", &membrane::SolveReport::cg_iterations)
      .def_readonly("converged", &membrane::SolveReport::converged);
}

void bind_plugin_material(py::module_& m) {
  py::enum_<bullet::MaterialModel>(m, "MaterialModel")
      .value("membrane", bullet::MaterialModel::membrane)
      .value("bullet_links", bullet::MaterialModel::bullet_links);
  py::class_<Material>(m, "Material",
                       "A skinned soft body's physical parameters, SI units "
                       "(bullet/skinned_soft_body.hpp). model: membrane (default) or "
                       "bullet_links; skin and solver: the membrane's.")
      .def(py::init<>())
      .def_readwrite("model", &Material::model)
      .def_readwrite("link_stiffness", &Material::link_stiffness)
      .def_readwrite("damping", &Material::damping)
      .def_readwrite("pretension", &Material::pretension)
      .def_readwrite("density", &Material::density, "bullet_links: kg/m^2")
      .def_readwrite("target_stiffness", &Material::target_stiffness, "bullet_links: 1/s^2")
      .def_readwrite("target_damping", &Material::target_damping, "bullet_links: 1/s")
      .def_readwrite("kinematic_weight", &Material::kinematic_weight)
      .def_readwrite("position_iterations", &Material::position_iterations)
      .def_readwrite("bending_stiffness", &Material::bending_stiffness)
      .def_readwrite("margin", &Material::margin, "m")
      .def_readwrite(
          "max_speed", &Material::max_speed,
          "world units/s: a node faster than this past its skinned target stops the step "
          "(default inf: no bound)")
      .def_readwrite("skin", &Material::skin)
      .def_readwrite("solver", &Material::solver);
}

}  // namespace

void bind_material(py::module_& m) {
  bind_skin(m);
  bind_solver(m);
  bind_plugin_material(m);
}

}  // namespace conform::python
