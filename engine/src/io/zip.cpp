// zlib deflates, inflates and checksums (it is the reference implementation of all three); the
// archive around them is a few fixed headers. Dates are 1980-01-01, so the same mesh gives the
// same bytes.
#include "io/zip.h"

#include <zlib.h>

#include <algorithm>
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

uint32_t get16(std::string_view s, size_t at) {
    return uint32_t(uint8_t(s[at])) | uint32_t(uint8_t(s[at + 1])) << 8;
}
uint32_t get32(std::string_view s, size_t at) {
    return get16(s, at) | get16(s, at + 2) << 16;
}

Error zipError(std::string text) {
    return Error::message(ErrorKind::Validation, {}, std::move(text));
}

std::string amount(uint64_t bytes) {
    return bytes % (1 << 20) == 0 ? std::to_string(bytes >> 20) + " MiB"
                                  : std::to_string(bytes) + " bytes";
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

Result<std::vector<ZipDirectoryEntry>> zipDirectory(std::string_view s) {
    // The end record (22 bytes and a comment of up to 64 KiB) is found from the file's end.
    if (s.size() < 22) return zipError("no ZIP directory that can be read");
    const size_t lowest = s.size() > 22 + 65535 ? s.size() - 22 - 65535 : 0;
    size_t end = s.size() - 22;
    for (; get32(s, end) != 0x06054b50u; --end)
        if (end == lowest) return zipError("no ZIP directory that can be read");
    const uint32_t count = get16(s, end + 10), offset = get32(s, end + 16);
    // ZIP64 marks the fields it moves elsewhere with all ones, and puts its locator before.
    if (count == 0xffff || offset == 0xffffffffu ||
        (end >= 20 && get32(s, end - 20) == 0x07064b50u))
        return zipError("a ZIP64 archive, which is not read");
    std::vector<ZipDirectoryEntry> entries;
    size_t at = offset;
    for (uint32_t e = 0; e < count; ++e) {
        if (at > end || end - at < 46 || get32(s, at) != 0x02014b50u)
            return zipError("a ZIP directory that runs past its end");
        ZipDirectoryEntry entry;
        entry.flags = get16(s, at + 8);
        entry.method = get16(s, at + 10);
        entry.crc = get32(s, at + 16);
        entry.packedSize = get32(s, at + 20);
        entry.size = get32(s, at + 24);
        entry.headerOffset = get32(s, at + 42);
        if (entry.packedSize == 0xffffffffu || entry.size == 0xffffffffu ||
            entry.headerOffset == 0xffffffffu)
            return zipError("a ZIP64 archive, which is not read");
        const size_t name = get16(s, at + 28), rest = size_t(get16(s, at + 30)) + get16(s, at + 32);
        if (end - at - 46 < name + rest) return zipError("a ZIP directory that runs past its end");
        entry.name = std::string(s.substr(at + 46, name));
        entries.push_back(std::move(entry));
        at += 46 + name + rest;
    }
    return entries;
}

Status zipUnpack(std::string_view s, const ZipDirectoryEntry& entry, uint64_t limit,
                 const std::function<bool(std::string_view)>& sink) {
    const std::string& name = entry.name;
    if (entry.flags & 1) return zipError(name + " is encrypted, which is not read");
    if (entry.method != 0 && entry.method != kDeflate)
        return zipError(name + " is compressed by method " + std::to_string(entry.method) +
                        ", which is not read (only stored and deflated)");
    if (entry.size > limit) return zipError(name + " unpacks to more than " + amount(limit));
    // The local header repeats the name and has its own extra field before the data.
    const uint64_t header = entry.headerOffset;
    if (header + 30 > s.size() || get32(s, size_t(header)) != 0x04034b50u)
        return zipError(name + " has no local header where the ZIP directory says");
    const uint64_t data =
        header + 30 + get16(s, size_t(header) + 26) + get16(s, size_t(header) + 28);
    if (data > s.size() || s.size() - data < entry.packedSize)
        return zipError(name + " runs past the file's end");
    const std::string_view packed = s.substr(size_t(data), size_t(entry.packedSize));

    uLong crc = crc32(0L, Z_NULL, 0);
    uint64_t total = 0;
    bool stopped = false;
    // Each piece counted before it is handed on: what a piece holds never passes either bound.
    auto deliver = [&](std::string_view piece) -> std::optional<Error> {
        total += piece.size();
        if (total > limit) return zipError(name + " unpacks to more than " + amount(limit));
        if (total > entry.size)
            return zipError(name + " unpacks to more than the " + std::to_string(entry.size) +
                            " bytes its ZIP directory declares");
        crc = crc32(crc, reinterpret_cast<const Bytef*>(piece.data()), uInt(piece.size()));
        stopped = !sink(piece);
        return std::nullopt;
    };
    constexpr size_t kPiece = size_t(1) << 20;
    if (entry.method == 0) {
        for (size_t at = 0; at < packed.size() && !stopped; at += kPiece)
            if (auto e = deliver(packed.substr(at, kPiece))) return *e;
    } else {
        z_stream z{};
        if (inflateInit2(&z, -MAX_WBITS) != Z_OK) return zipError("zlib could not start");
        std::string out(kPiece, '\0');
        std::optional<Error> problem;
        int status = Z_OK;
        size_t fed = 0;
        while (status != Z_STREAM_END && !stopped && !problem) {
            if (z.avail_in == 0 && fed < packed.size()) {
                const size_t n = std::min(packed.size() - fed, size_t(kPiece));
                z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(packed.data() + fed));
                z.avail_in = uInt(n);
                fed += n;
            }
            z.next_out = reinterpret_cast<Bytef*>(out.data());
            z.avail_out = uInt(out.size());
            status = inflate(&z, Z_NO_FLUSH);
            const size_t produced = out.size() - z.avail_out;
            if (status != Z_OK && status != Z_STREAM_END && status != Z_BUF_ERROR)
                problem = zipError(name + " is damaged: " + (z.msg ? z.msg : "bad deflate data"));
            else if (status == Z_BUF_ERROR && produced == 0 && fed == packed.size())
                problem = zipError(name + " is damaged: its deflated data ends early");
            else if (produced > 0)
                problem = deliver(std::string_view(out.data(), produced));
        }
        inflateEnd(&z);
        if (problem) return *problem;
    }
    if (stopped) return Ok{};
    if (total != entry.size)
        return zipError(name + " unpacks to " + std::to_string(total) + " bytes, not the " +
                        std::to_string(entry.size) + " its ZIP directory declares");
    if (uint32_t(crc) != entry.crc)
        return zipError(name + " is damaged: its CRC-32 does not match");
    return Ok{};
}

} // namespace sdfcsg::detail
