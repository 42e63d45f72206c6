// The plugin's last error (psc_last_error), per calling thread.
#pragma once

#include <string>

namespace psc_host {

// Records `message` as the calling thread's last error and returns `status`.
int fail(int status, std::string message);
const std::string& lastError();

}  // namespace psc_host
