// A ZIP archive (PKWARE's APPNOTE, the subset every reader takes: no ZIP64, no encryption), its
// entries deflated through zlib: the container of 3MF files, written and read.
#pragma once

#include "sdfcsg/error.h"

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace sdfcsg::detail {

struct ZipEntry {
    std::string_view name; // e.g. "3D/3dmodel.model"
    std::string_view data;
};

// The archive's bytes, or nullopt where it would pass what a ZIP without ZIP64 holds (4 GiB
// per entry and in all).
std::optional<std::string> zipArchive(std::span<const ZipEntry> entries);

// An entry as the archive's central directory describes it.
struct ZipDirectoryEntry {
    std::string name;
    uint32_t method = 0; // 0 stored, 8 deflated
    uint32_t flags = 0;
    uint32_t crc = 0;
    uint64_t packedSize = 0, size = 0; // size: what the directory says it unpacks to
    uint64_t headerOffset = 0;         // of its local header
};

// The archive's central directory, or the reason it cannot be read: no end record ("no ZIP
// directory that can be read"), ZIP64 (sizes of 4 GiB or more, which 3MF's parts never need),
// or a directory running past the file.
Result<std::vector<ZipDirectoryEntry>> zipDirectory(std::string_view archive);

// Unpacks `entry` of `archive` (stored or deflated, not encrypted), handing its bytes to `sink`
// in pieces of at most 1 MiB as they are inflated: a part is never held whole. Refused, with the
// reason, where it would unpack to more than `limit` bytes - judged on the bytes inflated, not
// only on the size its directory entry declares, which a hostile file can make small - or to
// more than that declared size, or where its CRC-32 does not match; `sink` returning false stops
// it, and it returns Ok: the caller knows why it stopped.
Status zipUnpack(std::string_view archive, const ZipDirectoryEntry& entry, uint64_t limit,
                 const std::function<bool(std::string_view)>& sink);

} // namespace sdfcsg::detail
