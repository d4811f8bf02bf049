// A SkinnedModel as bytes and back: how an import done in an isolated child (isolate.hpp)
// reaches the caller. Native byte order and sizes (the two ends are one build); not a file
// format. Decoding checks every count against the bytes left before it allocates, so a garbled
// message is an error, never a huge allocation or a read out of bounds.
#pragma once

#include <string>
#include <string_view>

#include "conform/io/model.hpp"

namespace conform::io {

std::string encode_model(const SkinnedModel& model);

/// Throws std::runtime_error ("model message: ...") when `bytes` is not one whole encoding.
SkinnedModel decode_model(std::string_view bytes);

}  // namespace conform::io
