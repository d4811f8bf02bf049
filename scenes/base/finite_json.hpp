// Finite or refused: a command's JSON output (summary.json, `ik --json`) is checked before it
// is written, since nlohmann-json writes NaN and ±inf as null and a reader would take that for
// a missing value.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace conform::scenes {

/// The dotted path (a.b[2].c) of the first NaN or infinite number in `value`, "" when every
/// number is finite; `key` is the path of `value` itself ("" at the top).
std::string first_non_finite(const nlohmann::json& value, const std::string& key = "");

/// Throws std::runtime_error "WHAT: KEY is NaN or infinite (VALUE)" for the first such number.
void require_finite(const nlohmann::json& value, const std::string& what);

}  // namespace conform::scenes
