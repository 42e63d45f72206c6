// ---- psc template: host code shared by the plugin's backends -------------

#include <algorithm>
#include <condition_variable>
#include <cstring>
#include <cstdlib>
#include <functional>
#include <memory>
#include <mutex>
#include <new>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

namespace psc_game {
namespace {

thread_local std::string lastError;

int fail(int status, std::string message) {
    lastError = std::move(message);
    return status;
}

}  // namespace
}  // namespace psc_game
