// The Python module `conform`: the scenes of the `conform` command, a Bullet soft world with
// CGA-skinned bodies that are cut, torn and drilled at run time, and the closed-form arm IK.
#include "bindings.hpp"
#include "conform/version.hpp"

PYBIND11_MODULE(conform, m) {
  namespace cp = conform::python;
  m.doc() =
      "Conform: CGA skinning, run-time cut / tear / drill of skinned Bullet soft bodies, the "
      "skin membrane and the closed-form CGA arm IK.";
  m.attr("__version__") = conform::version();
  cp::bind_errors(m);
  cp::bind_scenes(m);
  cp::bind_material(m);
  cp::bind_world(m);
  cp::bind_ik(m);
}
