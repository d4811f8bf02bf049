#pragma once

namespace conform {
/// The library's version, "MAJOR.MINOR.PATCH".
const char* version();
}  // namespace conform
