#include "conform/version.hpp"

namespace conform {
const char* version() { return CONFORM_VERSION; }
}  // namespace conform
