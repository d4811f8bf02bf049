// The budget and the failures of an isolated import: how long a file may take to read, and
// the ImportError that names why an isolated import ended without a model.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "conform/io/import.hpp"
#include "conform/io/isolate.hpp"
#include "conform/io/isolation_limits.hpp"

namespace conform::io {

/// The bytes a reader of `path` may read: the file, and the files beside it with the same stem
/// (a .gltf's .bin, an .md5mesh's .md5anim); for a .gltf, whose buffers may have any name, every
/// file of its folder.
std::uintmax_t import_bytes(const std::filesystem::path& path);

/// The import error for an isolated import of `file` that did not end with a model, under
/// `limits` (those the import ran with, its time budget included).
ImportError isolation_error(const std::string& file, const Isolated& r,
                            const IsolationLimits& limits);

}  // namespace conform::io
