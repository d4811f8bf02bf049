// The pieces of the Python module `conform`, one concept per file: errors, scenes, the material,
// the soft world, the skinned body (its state and pose, its arrays, its edits) and the arm IK.
#pragma once

#include <pybind11/pybind11.h>

namespace conform::python {

namespace py = pybind11;

/// Library exceptions as Python exceptions with the same message (errors.cpp).
void bind_errors(py::module_& m);
/// run, scenes, scene_json, sweep (scenes.cpp).
void bind_scenes(py::module_& m);
/// Material, SkinMaterial, SolverSettings and their enums (material.cpp).
void bind_material(py::module_& m);
/// World and Body (world.cpp, body.cpp, body_arrays.cpp, body_edits.cpp).
void bind_world(py::module_& m);
/// The submodule conform.ik (ik.cpp).
void bind_ik(py::module_& m);

}  // namespace conform::python
