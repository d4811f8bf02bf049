#include "import_budget.hpp"

#include <cctype>
#include <sstream>
#include <system_error>

namespace conform::io {

double import_seconds(const IsolationLimits& limits, std::uintmax_t file_bytes) {
  return limits.seconds + limits.seconds_per_mib * (double(file_bytes) / 1048576.0);
}

std::uintmax_t import_bytes(const std::filesystem::path& path) {
  std::error_code ec;
  std::uintmax_t bytes = std::filesystem::file_size(path, ec);
  if (ec) bytes = 0;
  std::string ext = path.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const bool whole_folder = ext == ".gltf";
  const std::filesystem::path folder = path.has_parent_path() ? path.parent_path() : ".";
  for (std::filesystem::directory_iterator it(folder, ec), end; !ec && it != end;
       it.increment(ec)) {
    std::error_code e;
    if (it->path().filename() == path.filename() || !it->is_regular_file(e)) continue;
    if (whole_folder || it->path().stem() == path.stem()) {
      const std::uintmax_t size = it->file_size(e);
      if (!e) bytes += size;
    }
  }
  return bytes;
}

ImportError isolation_error(const std::string& file, const Isolated& r,
                            const IsolationLimits& limits) {
  using S = Isolated::Status;
  std::ostringstream why;
  switch (r.status) {
    case S::failed:  // the child's ImportError ("file: problem") or another exception's what()
      if (r.message.find("bad_alloc") == std::string::npos)
        return ImportError(file, r.message.rfind(file + ": ", 0) == 0
                                     ? r.message.substr(file.size() + 2)
                                     : r.message);
      [[fallthrough]];  // assimp caught std::bad_alloc and reports it as its error
    case S::out_of_memory:
      why << "reading it ran out of memory (the import's cap is " << limits.memory_bytes / 1048576.0
          << " MiB: ImportOptions::isolation.memory_bytes, --import-memory); the file is corrupt "
             "or too large";
      break;
    case S::timed_out:
      why << "reading it did not finish within " << limits.seconds
          << " s (its budget: ImportOptions::isolation.seconds + seconds_per_mib per MiB, "
             "--import-seconds, --import-seconds-per-mib); the file is corrupt or too large";
      break;
    case S::crashed:
      why << "assimp crashed reading it (" << r.message
          << "); the file is corrupt (e.g. bone or vertex indices out of range) or its node "
             "hierarchy too deep";
      break;
    default:
      why << "could not start the isolated import (" << r.message << ")";
  }
  return ImportError(file, why.str());
}

}  // namespace conform::io
