// conform.World: a Bullet soft world with gravity and a ground, the plugin attached; add_arm /
// add_model add skinned soft bodies, step advances the simulation.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <string>

#include "body.hpp"
#include "conform/io/import.hpp"
#include "conform/skin/procedural_arm.hpp"
#include "kinds/model_frame.hpp"

namespace conform::python {

namespace {
constexpr double kGroundHalfThickness = 0.05;  // m
}  // namespace

World::World(const Eigen::Vector3d& gravity, std::optional<double> ground_height)
    : soft(btVector3(btScalar(gravity.x()), btScalar(gravity.y()), btScalar(gravity.z()))) {
  if (!gravity.allFinite()) throw std::invalid_argument("gravity is not finite");
  if (ground_height) {
    if (!std::isfinite(*ground_height)) throw std::invalid_argument("ground height is not finite");
    // A thin box, not a btStaticPlaneShape: Bullet's soft-rigid contacts sample a signed
    // distance grid that only convex shapes have (docs/library.md, "Free pieces and collisions").
    ground_shape = std::make_unique<btBoxShape>(btVector3(50, btScalar(kGroundHalfThickness), 50));
    ground_motion = std::make_unique<btDefaultMotionState>(
        btTransform(btQuaternion::getIdentity(),
                    btVector3(0, btScalar(*ground_height - kGroundHalfThickness), 0)));
    ground = std::make_unique<btRigidBody>(
        btRigidBody::btRigidBodyConstructionInfo(0, ground_motion.get(), ground_shape.get()));
    soft.world.addRigidBody(ground.get());
  }
  plugin = std::make_unique<bullet::Plugin>(soft.world);
}

World::~World() {
  plugin.reset();  // the plugin's bodies leave the world first
  if (ground) soft.world.removeRigidBody(ground.get());
}

namespace {

void step(World& w, double dt, int substeps) {
  if (!(dt > 0) || !std::isfinite(dt))
    throw std::invalid_argument("dt = " + std::to_string(dt) + ": must be positive and finite");
  if (substeps < 1)
    throw std::invalid_argument("substeps = " + std::to_string(substeps) + ": must be >= 1");
  w.soft.step(dt / substeps, substeps);
}

Body add_arm(const py::object& self, const bullet::Material& material, int resolution, int segments,
             int rings) {
  skin::ArmOptions o;
  o.resolution = resolution, o.segments = segments, o.rings = rings;
  const skin::Arm arm = skin::make_arm(o);
  World& w = self.cast<World&>();
  return make_body(self, w.plugin->add_skinned_body(arm.mesh, arm.skeleton, material));
}

// File units per metre: the given number, else (None) the file's own (scenes::file_units), as
// the character scene reads model.units_per_metre = "file"; the procedural arm ("arm",
// "arm:N") is in metres already.
double units_per_metre(const io::SkinnedModel& model, const std::string& file,
                       const std::optional<double>& given) {
  if (given) {
    if (!(*given >= 1e-6 && *given <= 1e6))
      throw std::invalid_argument("units_per_metre = " + std::to_string(*given) +
                                  " is out of range [1e-06, 1e+06]");
    return *given;
  }
  if (file.rfind("arm", 0) == 0 && model.source.rfind("arm", 0) == 0) return 1;
  return scenes::file_units(model, file).units_per_metre;
}

Body add_model(const py::object& self, const std::string& file, const bullet::Material& material,
               const std::optional<double>& units, const std::string& up) {
  io::SkinnedModel model = io::load_model(file);
  scenes::to_scene_frame(model, {units_per_metre(model, file, units), up});
  World& w = self.cast<World&>();
  Body b = make_body(self, w.plugin->add_skinned_body(model, material));
  b.animations = std::move(model.animations);
  return b;
}

}  // namespace

void bind_world(py::module_& m) {
  py::class_<World>(m, "World",
                    "A Bullet soft-rigid world with gravity (m/s^2) and a ground whose top is y = "
                    "ground (a static box 10 cm thick; None: none), the Conform plugin attached. "
                    "It owns its bodies.")
      .def(py::init<const Eigen::Vector3d&, std::optional<double>>(),
           py::arg("gravity") = Eigen::Vector3d(0, -9.81, 0), py::arg("ground") = -0.5)
      .def("add_arm", &add_arm, py::arg("material") = bullet::Material{}, py::arg("resolution") = 1,
           py::arg("segments") = 0, py::arg("rings") = 0,
           "Adds the procedural arm (shoulder at the origin, along +z; bones shoulder, elbow, "
           "wrist) as a skinned soft body.")
      .def("add_model", &add_model, py::arg("file"), py::arg("material") = bullet::Material{},
           py::arg("units_per_metre") = py::none(), py::arg("up") = "y",
           "Adds a rigged model file (assimp; 'arm' or 'arm:N' for the procedural arm), brought "
           "to metres and Y up as the character scene does: units_per_metre file units make a "
           "metre (None: the unit the file states, else metres), up ('y' or 'z') is the file's up "
           "axis. Raises ModelImportError for a file that cannot be read.")
      .def("step", &step, py::arg("dt") = 1.0 / 60, py::arg("substeps") = 1,
           "Advances dt seconds in `substeps` equal substeps. Raises NonFiniteState when the "
           "simulation goes non-finite.")
      .def_property_readonly(
          "time", [](const World& w) { return w.plugin->time(); }, "Simulated time, s.")
      .def_property_readonly(
          "substeps", [](const World& w) { return w.plugin->substeps(); }, "Substeps taken.")
      .def_property_readonly("body_count",
                             [](const World& w) { return w.plugin->skinned_body_count(); });
  py::class_<Body> body(m, "Body",
                        "A CGA-skinned soft body of a World (World.add_arm, World.add_model).");
  bind_body_state(body);
  bind_body_arrays(body);
  bind_body_edits(body);
}

}  // namespace conform::python
