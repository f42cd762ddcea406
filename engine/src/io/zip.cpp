// zlib deflates and checksums (it is the reference implementation of both); the archive around
// them is a few fixed headers. Dates are 1980-01-01, so the same mesh gives the same bytes.
#include "io/zip.h"

#include <zlib.h>

#include <cstdint>
#include <limits>
#include <vector>

namespace sdfcsg::detail {
namespace {

void put16(std::string& out, uint32_t v) {
    out.push_back(char(v & 0xff));
    out.push_back(char((v >> 8) & 0xff));
}
void put32(std::string& out, uint32_t v) {
    put16(out, v & 0xffff);
    put16(out, v >> 16);
}

// Raw deflate (no zlib header, as ZIP's method 8 wants), or nullopt past 4 GiB. The fastest
// level: a mesh's XML shrinks about 6x at it, and writing stays a small part of meshing.
std::optional<std::string> deflateRaw(std::string_view data) {
    z_stream z{};
    if (deflateInit2(&z, Z_BEST_SPEED, Z_DEFLATED, -15, 8, Z_DEFAULT_STRATEGY) != Z_OK)
        return std::nullopt;
    std::string out;
    out.resize(deflateBound(&z, uLong(data.size())));
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
    z.avail_in = uInt(data.size());
    z.next_out = reinterpret_cast<Bytef*>(out.data());
    z.avail_out = uInt(out.size());
    const int status = deflate(&z, Z_FINISH);
    out.resize(z.total_out);
    deflateEnd(&z);
    if (status != Z_STREAM_END) return std::nullopt;
    return out;
}

constexpr uint32_t kDate = (0 << 9) | (1 << 5) | 1; // 1980-01-01 in DOS form
constexpr uint32_t kVersion = 20;                   // 2.0: deflate
constexpr uint32_t kDeflate = 8;

} // namespace

std::optional<std::string> zipArchive(std::span<const ZipEntry> entries) {
    constexpr size_t kMax = std::numeric_limits<uint32_t>::max();
    std::string out, directory;
    for (const ZipEntry& e : entries) {
        if (e.data.size() >= kMax || e.data.size() > std::numeric_limits<uInt>::max())
            return std::nullopt;
        auto packed = deflateRaw(e.data);
        if (!packed || out.size() + packed->size() + 64 + e.name.size() >= kMax)
            return std::nullopt;
        const uint32_t crc =
            uint32_t(crc32(crc32(0L, Z_NULL, 0), reinterpret_cast<const Bytef*>(e.data.data()),
                           uInt(e.data.size())));
        const uint32_t offset = uint32_t(out.size());
        // The fields from "version needed" to the name's length, the same in both headers.
        std::string common;
        put16(common, kVersion);
        put16(common, 0); // flags
        put16(common, kDeflate);
        put16(common, 0); // time
        put16(common, kDate);
        put32(common, crc);
        put32(common, uint32_t(packed->size()));
        put32(common, uint32_t(e.data.size()));
        put16(common, uint32_t(e.name.size()));
        put16(common, 0); // extra field length

        put32(out, 0x04034b50);
        out += common;
        out += e.name;
        out += *packed;

        put32(directory, 0x02014b50);
        put16(directory, kVersion); // made by
        directory += common;
        put16(directory, 0); // comment length
        put16(directory, 0); // disk
        put16(directory, 0); // internal attributes
        put32(directory, 0); // external attributes
        put32(directory, offset);
        directory += e.name;
    }
    if (out.size() + directory.size() + 22 >= kMax || entries.size() > 0xffff) return std::nullopt;
    const uint32_t directoryAt = uint32_t(out.size());
    out += directory;
    put32(out, 0x06054b50);
    put16(out, 0); // this disk
    put16(out, 0); // the directory's disk
    put16(out, uint32_t(entries.size()));
    put16(out, uint32_t(entries.size()));
    put32(out, uint32_t(directory.size()));
    put32(out, directoryAt);
    put16(out, 0); // comment length
    return out;
}

} // namespace sdfcsg::detail
