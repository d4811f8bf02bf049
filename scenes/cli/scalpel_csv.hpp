// The scalpel file of `conform tear --scalpel`: a CSV whose header is t,ax,ay,az,bx,by,bz and
// whose every other non-blank line is one sample, the time and the blade's two ends. Read
// strictly: exactly those seven columns, every cell a finite number.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "conform/mesh/tear.hpp"

namespace conform::scenes {

/// The samples of the CSV text `text` read from `file` (named in errors). Throws
/// std::runtime_error naming the file, line and column of the first problem.
std::vector<mesh::ScalpelSample> parse_scalpel_csv(std::string_view text, const std::string& file);

/// The samples of the scalpel file `file`, read through read_bounded (bounded_read.hpp).
std::vector<mesh::ScalpelSample> read_scalpel_csv(const std::string& file);

}  // namespace conform::scenes
