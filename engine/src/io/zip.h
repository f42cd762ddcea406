// A ZIP archive (PKWARE's APPNOTE, the subset every reader takes: no ZIP64, no encryption), its
// entries deflated through zlib: the container of 3MF files.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace sdfcsg::detail {

struct ZipEntry {
    std::string_view name; // e.g. "3D/3dmodel.model"
    std::string_view data;
};

// The archive's bytes, or nullopt where it would pass what a ZIP without ZIP64 holds (4 GiB
// per entry and in all).
std::optional<std::string> zipArchive(std::span<const ZipEntry> entries);

} // namespace sdfcsg::detail
