#include "DeviceImage.h"

#include <cstring>

namespace psc_host {
namespace {

void putWord(std::string& out, uint64_t w) {
    for (int i = 0; i < 8; ++i) out += static_cast<char>((w >> (8 * i)) & 0xff);
}

// Reads a u64 at `*at`, advancing it; false past the end.
bool getWord(std::string_view bytes, size_t* at, uint64_t* w) {
    if (bytes.size() < 8 || *at > bytes.size() - 8) return false;
    *w = 0;
    for (int i = 0; i < 8; ++i) *w |= static_cast<uint64_t>(static_cast<unsigned char>(bytes[*at + i])) << (8 * i);
    *at += 8;
    return true;
}

}  // namespace

std::string encodeDeviceImage(const DeviceImage& image) {
    std::string out(kDeviceImageMagic, sizeof kDeviceImageMagic);
    putWord(out, image.stackBytes);
    putWord(out, image.cubin.size());
    putWord(out, image.ptx.size());
    for (const auto& unit : image.ptx) putWord(out, unit.size());
    out += image.cubin;
    for (const auto& unit : image.ptx) {
        out += unit;
        out += '\0';
    }
    return out;
}

bool decodeDeviceImage(std::string_view bytes, DeviceImage* image, std::string* error) {
    auto bad = [&](const char* why) {
        *error = std::string("the device code is damaged: ") + why;
        return false;
    };
    if (bytes.size() < sizeof kDeviceImageMagic || std::memcmp(bytes.data(), kDeviceImageMagic, sizeof kDeviceImageMagic) != 0) {
        return bad("it does not start with psc's mark (a plugin of another psc version?)");
    }
    size_t at = sizeof kDeviceImageMagic;
    uint64_t stack = 0, cubin = 0, units = 0;
    if (!getWord(bytes, &at, &stack) || !getWord(bytes, &at, &cubin) || !getWord(bytes, &at, &units)) return bad("short header");
    if (units == 0 || units > (bytes.size() - at) / 8) return bad("impossible number of compile units");
    std::vector<uint64_t> sizes(units);
    for (auto& s : sizes) getWord(bytes, &at, &s);
    if (cubin > bytes.size() - at) return bad("the cubin runs past the end");
    DeviceImage out;
    out.stackBytes = stack;
    out.cubin.assign(bytes.substr(at, cubin));
    at += cubin;
    for (uint64_t s : sizes) {
        if (s >= bytes.size() - at || bytes[at + s] != '\0') return bad("a compile unit's PTX runs past the end");
        out.ptx.emplace_back(bytes.substr(at, s));
        at += s + 1;
    }
    if (at != bytes.size()) return bad("bytes after the last compile unit");
    *image = std::move(out);
    return true;
}

}  // namespace psc_host
