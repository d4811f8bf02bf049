// conform.Body: state, pieces and their events, the pose sources.
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <string>

#include "body.hpp"

namespace conform::python {

void Body::check_no_views(const char* edit) const {
  if (*views == 0) return;
  throw py::buffer_error(std::string(edit) + ": " + std::to_string(*views) +
                         " zero-copy array view(s) of this body's vertex or face storage are "
                         "alive, and an edit may move that storage; copy them (numpy.array(v)) "
                         "or delete them (del v) first");
}

std::int32_t Body::vertex(std::int32_t v) const {
  if (v < 0 || v >= body->vertex_count())
    throw std::out_of_range("vertex " + std::to_string(v) + " out of range [0, " +
                            std::to_string(body->vertex_count()) + ")");
  return v;
}

void Body::deliver_events() {
  std::vector<bullet::PieceEvent> now;
  now.swap(events->undelivered);
  for (const auto& e : now)
    for (const auto& f : events->listeners) f(e);
}

Body make_body(const py::object& world, bullet::SkinnedSoftBody& body) {
  Body b;
  b.body = &body;
  b.world = world;
  std::weak_ptr<PieceEvents> events = b.events;
  body.on_piece_event([events](const bullet::PieceEvent& e) {
    if (auto ev = events.lock()) {
      ev->log.push_back(e);
      if (e.kind != bullet::PieceEvent::Kind::body_destroyed) ev->undelivered.push_back(e);
    }
  });
  return b;
}

namespace {

using PieceTuple = std::pair<std::int32_t, std::uint32_t>;

bullet::PieceId piece(const PieceTuple& t) {
  return {t.first, t.second};
}
PieceTuple tuple(const bullet::PieceId& id) {
  return {id.index, id.generation};
}

std::int32_t joint_index(const skin::Skeleton& sk, const py::handle& key) {
  if (py::isinstance<py::str>(key)) {
    const std::string name = key.cast<std::string>();
    const std::int32_t j = sk.find_joint(name);
    if (j < 0) throw std::invalid_argument("no joint named '" + name + "'");
    return j;
  }
  const auto j = key.cast<std::int32_t>();
  if (j < 0 || j >= sk.joint_count())
    throw std::out_of_range("joint " + std::to_string(j) + " out of range [0, " +
                            std::to_string(sk.joint_count()) + ")");
  return j;
}

// {joint: quaternion (w, x, y, z)} or {joint: (quaternion, translation)}: local transforms on
// the rest pose (a joint given a rotation only keeps its rest translation).
skin::Pose make_pose(const skin::Skeleton& sk, const py::dict& joints) {
  skin::Pose pose = skin::Pose::rest(sk);
  for (const auto& [key, value] : joints) {
    const std::int32_t j = joint_index(sk, key);
    const skin::Versor& rest = sk.joints[static_cast<std::size_t>(j)].rest;
    Eigen::Vector3d t = rest.motor.translation();
    Eigen::Vector4d q;
    const auto seq = value.cast<py::sequence>();
    if (py::len(seq) == 2) {
      q = seq[0].cast<Eigen::Vector4d>();
      t = seq[1].cast<Eigen::Vector3d>();
    } else {
      q = value.cast<Eigen::Vector4d>();
    }
    if (!q.allFinite() || q.norm() == 0 || !t.allFinite())
      throw std::invalid_argument("joint " + std::to_string(j) +
                                  ": the rotation must be a finite non-zero quaternion (w, x, y, "
                                  "z) and the translation finite");
    pose.local[static_cast<std::size_t>(j)] = skin::Versor::from_trs(
        t, Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized(), rest.scale);
  }
  return pose;
}

void set_keyframes(Body& b, const std::vector<double>& times, const py::list& poses) {
  if (times.size() != py::len(poses))
    throw std::invalid_argument("set_keyframes: " + std::to_string(times.size()) + " times but " +
                                std::to_string(py::len(poses)) + " poses");
  skin::PoseTrack track;
  for (std::size_t i = 0; i < times.size(); ++i)
    track.set_key(times[i], make_pose(b.get().skeleton(), poses[i].cast<py::dict>()));
  b.get().set_keyframes(std::move(track));
}

void play(Body& b, const py::object& animation, bool loop) {
  int index = -1;
  if (py::isinstance<py::str>(animation)) {
    const auto name = animation.cast<std::string>();
    for (std::size_t i = 0; i < b.animations.size(); ++i)
      if (b.animations[i].name == name) index = static_cast<int>(i);
    if (index < 0) throw std::invalid_argument("no animation named '" + name + "'");
  } else {
    index = animation.cast<int>();
    if (index < 0 || index >= static_cast<int>(b.animations.size()))
      throw std::out_of_range("animation " + std::to_string(index) + " out of range [0, " +
                              std::to_string(b.animations.size()) + ")");
  }
  b.get().play(b.animations[static_cast<std::size_t>(index)], skin::Blend::linear, loop);
}

// The arm's pose from the IK's quaternions: shoulder qs at the origin, elbow qe at
// (0, 0, upper), as the arm-track scene places them.
void set_arm_pose(Body& b, const Eigen::Vector4d& qs, const Eigen::Vector4d& qe, double upper) {
  py::dict joints;
  joints[py::int_(0)] = py::make_tuple(qs, Eigen::Vector3d(0, 0, 0));
  joints[py::int_(1)] = py::make_tuple(qe, Eigen::Vector3d(0, 0, upper));
  b.get().set_pose(make_pose(b.get().skeleton(), joints));
}

void release(Body& b, const PieceTuple& id, double link_stiffness, double volume_modulus,
             double pressure) {
  bullet::ReleaseOptions o;
  o.link_stiffness = link_stiffness, o.volume_modulus = volume_modulus, o.pressure = pressure;
  b.get().release_piece(piece(id), o);
  b.deliver_events();
}

void bind_pieces(py::class_<Body>& c) {
  py::enum_<bullet::PieceEvent::Kind>(c, "PieceEventKind")
      .value("created", bullet::PieceEvent::Kind::created)
      .value("removed", bullet::PieceEvent::Kind::removed)
      .value("body_destroyed", bullet::PieceEvent::Kind::body_destroyed);
  py::class_<bullet::PieceEvent>(c, "PieceEvent")
      .def_readonly("kind", &bullet::PieceEvent::kind)
      .def_property_readonly("piece", [](const bullet::PieceEvent& e) { return tuple(e.piece); })
      .def_property_readonly("parent", [](const bullet::PieceEvent& e) { return tuple(e.parent); })
      .def("__repr__", [](const bullet::PieceEvent& e) {
        const char* k[] = {"created", "removed", "body_destroyed"};
        return std::string("PieceEvent(") + k[static_cast<int>(e.kind)] + ", piece=(" +
               std::to_string(e.piece.index) + ", " + std::to_string(e.piece.generation) +
               "), parent=(" + std::to_string(e.parent.index) + ", " +
               std::to_string(e.parent.generation) + "))";
      });
  c.def(
       "piece_ids",
       [](const Body& b) {
         std::vector<PieceTuple> out;
         for (const auto& id : b.get().piece_ids()) out.push_back(tuple(id));
         return out;
       },
       "The live pieces as (slot, generation) ids.")
      .def("piece_valid",
           [](const Body& b, const PieceTuple& id) { return b.get().piece_valid(piece(id)); })
      .def("piece_of",
           [](const Body& b, std::int32_t v) { return tuple(b.get().piece_of(b.vertex(v))); })
      .def("piece_released",
           [](const Body& b, const PieceTuple& id) { return b.get().piece_released(piece(id)); })
      .def("release", &release, py::arg("piece"), py::arg("link_stiffness") = 0.9,
           py::arg("volume_modulus") = 0.0, py::arg("pressure") = 0.0,
           "Releases a piece from skinning: it falls and collides, held by Bullet's links.")
      .def(
          "on_piece_event",
          [](Body& b, py::object f) { b.events->listeners.push_back(std::move(f)); },
          "Calls f(event) for every piece created or removed by a later edit, after the edit.")
      .def(
          "events",
          [](Body& b) {
            std::vector<bullet::PieceEvent> out;
            out.swap(b.events->log);
            return out;
          },
          "The piece events since the last call (created and removed pieces), oldest first.");
}

void bind_pose(py::class_<Body>& c) {
  c.def(
       "set_pose",
       [](Body& b, const py::dict& joints) {
         b.get().set_pose(make_pose(b.get().skeleton(), joints));
       },
       py::arg("joints"),
       "A fixed pose: {joint (index or name): quaternion (w, x, y, z) or (quaternion, "
       "translation)} on the rest pose.")
      .def("set_arm_pose", &set_arm_pose, py::arg("qs"), py::arg("qe"), py::arg("upper") = 0.30,
           "The procedural arm's pose from the IK's shoulder and elbow quaternions.")
      .def("set_keyframes", &set_keyframes, py::arg("times"), py::arg("poses"),
           "Keyframes (times in s, poses as for set_pose), sampled at the simulated time.")
      .def("play", &play, py::arg("animation") = 0, py::arg("loop") = true,
           "Plays a model file's animation (index or name) at the simulated time.")
      .def_property_readonly("animations",
                             [](const Body& b) {
                               std::vector<std::string> names;
                               for (const auto& a : b.animations) names.push_back(a.name);
                               return names;
                             })
      .def("snap_to_pose", [](Body& b) { b.get().snap_to_pose(); })
      .def("set_pinned", [](Body& b, const std::vector<std::int32_t>& v) { b.get().set_pinned(v); })
      .def_property_readonly("joint_names", [](const Body& b) {
        std::vector<std::string> names;
        for (const auto& j : b.get().skeleton().joints) names.push_back(j.name);
        return names;
      });
}

void bind_scalars(py::class_<Body>& c) {
  using B = const Body&;
  c.def_property_readonly("vertex_count", [](B b) { return b.get().vertex_count(); })
      .def_property_readonly("face_count", [](B b) { return b.get().mesh().face_count(); })
      .def_property_readonly("piece_count", [](B b) { return b.get().piece_count(); })
      .def_property_readonly("link_count", [](B b) { return b.get().link_count(); })
      .def_property_readonly("detached_count", [](B b) { return b.get().detached_count(); })
      .def_property_readonly("topology_version", [](B b) { return b.get().topology_version(); })
      .def_property_readonly(
          "total_mass", [](B b) { return b.get().total_mass(); }, "kg")
      .def_property_readonly(
          "momentum", [](B b) { return b.get().momentum(); }, "kg m/s")
      .def_property_readonly("momentum_scale", [](B b) { return b.get().momentum_scale(); })
      .def_property_readonly("last_solve", [](B b) { return b.get().last_solve(); })
      .def_property_readonly(
          "material", [](B b) { return b.get().material(); }, "A copy.")
      .def("position", [](B b, std::int32_t v) { return b.get().position(b.vertex(v)); })
      .def("velocity", [](B b, std::int32_t v) { return b.get().velocity(b.vertex(v)); })
      .def("target", [](B b, std::int32_t v) { return b.get().target(b.vertex(v)); })
      .def("mass", [](B b, std::int32_t v) { return b.get().mass(b.vertex(v)); })
      .def(
          "sync", [](Body& b) { b.get().sync_mesh(); },
          "Copies the simulated positions into the mesh (what the positions view shows).");
}

}  // namespace

void bind_body_state(py::class_<Body>& c) {
  bind_scalars(c);
  bind_pieces(c);
  bind_pose(c);
}

}  // namespace conform::python
