// A CUDA plugin's device code as one block of bytes: the linked cubin, each
// compile unit's PTX (for GPUs the cubin is not for) and the kernels' stack
// bound.  psc adds it to the linked plugin as a section of its own
// (kDeviceImageSection, not loaded with the plugin) once NVRTC is done, so
// that the plugin's host side can compile and link while NVRTC runs; the CUDA
// backend reads it back from the plugin's file (PluginFile.h).
//
// Layout, little-endian: the 8 bytes of kDeviceImageMagic; u64 stack bytes a
// thread, u64 cubin bytes, u64 PTX units, then a u64 a unit (its PTX's bytes);
// then the cubin, then each unit's PTX followed by a NUL byte.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace psc_host {

constexpr char kDeviceImageSection[] = ".psc_device";
constexpr char kDeviceImageMagic[8] = {'p', 's', 'c', 'd', 'e', 'v', '1', '\0'};

struct DeviceImage {
    std::string cubin;
    std::vector<std::string> ptx;  // each compile unit's
    uint64_t stackBytes = 0;       // per thread, a bound on the kernels' stacks
};

std::string encodeDeviceImage(const DeviceImage& image);
// False, with the reason in *error, when `bytes` is not an image encodeDeviceImage made.
bool decodeDeviceImage(std::string_view bytes, DeviceImage* image, std::string* error);

}  // namespace psc_host
