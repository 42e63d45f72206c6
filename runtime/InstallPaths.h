// Where psc's own libraries are: lib/psc beside the bin/ folder of the
// running executable once installed; in the build tree, <build>/lib/psc,
// the same place relative to cli/ and tests/.
#pragma once

#include <string>

namespace psc {

// The folder lib/psc, or "" when the running executable cannot be found.
std::string pscLibraryDir();

// The plugin host (runtime/plugin_host), linked into every plugin.
constexpr const char* kPluginHostFile = "libpsc_plugin_host.a";

}  // namespace psc
