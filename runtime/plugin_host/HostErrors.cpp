#include "HostErrors.h"

namespace psc_host {
namespace {
thread_local std::string lastErrorText;
}  // namespace

int fail(int status, std::string message) {
    lastErrorText = std::move(message);
    return status;
}

const std::string& lastError() { return lastErrorText; }

}  // namespace psc_host
