// sdfcsg: file output that is whole or absent.
#pragma once

#include "sdfcsg/error.h"

#include <filesystem>
#include <string_view>

namespace sdfcsg {

// Writes `data` to a temporary file beside `path`, then renames it over `path`, so readers see
// either the old file or the complete new one, never a partial write. On failure the temporary
// is removed and an Io error names `path`.
Status writeFileAtomic(const std::filesystem::path& path, std::string_view data);

} // namespace sdfcsg
