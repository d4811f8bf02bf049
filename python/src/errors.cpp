// Library exceptions become Python exceptions with the same message. pybind11 already maps
// std::invalid_argument, std::domain_error and std::length_error to ValueError,
// std::out_of_range to IndexError and std::runtime_error (and any other std::exception) to
// RuntimeError; the library's own classes get their own Python classes here:
//   conform.SceneError (ValueError)        a bad scene key or value (scenes::SceneError)
//   conform.NonFiniteState (RuntimeError)  the simulation went NaN / inf (bullet::NonFiniteState)
//   conform.ModelImportError (RuntimeError) a model file that cannot be read (io::ImportError)
//   conform.LogicError (RuntimeError)      a call the API forbids (std::logic_error), e.g. an
//                                          edit from inside a step
#include <stdexcept>

#include "base/scene_config.hpp"
#include "bindings.hpp"
#include "conform/bullet/non_finite_state.hpp"
#include "conform/io/import.hpp"

namespace conform::python {

void bind_errors(py::module_& m) {
  static py::exception<scenes::SceneError> scene_error(m, "SceneError", PyExc_ValueError);
  static py::exception<bullet::NonFiniteState> non_finite(m, "NonFiniteState", PyExc_RuntimeError);
  static py::exception<io::ImportError> import_error(m, "ModelImportError", PyExc_RuntimeError);
  static py::exception<std::logic_error> logic_error(m, "LogicError", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const scenes::SceneError& e) {
      scene_error(e.what());
    } catch (const bullet::NonFiniteState& e) {
      non_finite(e.what());
    } catch (const io::ImportError& e) {
      import_error(e.what());
    } catch (const std::invalid_argument&) {
      throw;  // ValueError (pybind11's own translation)
    } catch (const std::domain_error&) {
      throw;
    } catch (const std::length_error&) {
      throw;
    } catch (const std::out_of_range&) {
      throw;
    } catch (const std::logic_error& e) {
      logic_error(e.what());
    }
  });
}

}  // namespace conform::python
