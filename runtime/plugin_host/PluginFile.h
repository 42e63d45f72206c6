// The plugin's own file, read back for what is not loaded with it: a section
// psc added after the link (DeviceImage.h).
#pragma once

#include <string>

namespace psc_host {

// The path of the file this code was loaded from: the mapping that holds it
// (/proc/self/maps, which names the file however dlopen was given it), else
// what dladdr says.
std::string pluginFilePath();

// The bytes of the section `name` of the ELF file at `path`; false, with the
// reason in *error, when the file cannot be read, is not a 64-bit ELF file or
// has no such section.
bool readElfSection(const std::string& path, const char* name, std::string* bytes, std::string* error);

}  // namespace psc_host
