#include "kinds/event_time.hpp"

#include <sstream>

#include "base/scene_config.hpp"

namespace conform::scenes {

void require_before_end(const CommonSettings& c, const std::string& key, double value,
                        const std::string& what, double time) {
  const double end = c.steps * c.dt;
  if (event_due(end, time)) return;
  std::ostringstream why;
  why << what;
  if (time != value) why << " at " << time << " s";
  why << " is after the last step: the scene ends at " << end << " s (" << c.steps << " steps of "
      << c.dt << " s)";
  throw SceneError(key, show(Json(value)), why.str());
}

}  // namespace conform::scenes
