#include "Progress.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

namespace psc::play {
namespace fs = std::filesystem;

namespace {

fs::path stateDirectory() {
    const char* xdg = std::getenv("XDG_STATE_HOME");
    if (xdg && *xdg) return fs::path(xdg) / "psc" / "play";
    const char* home = std::getenv("HOME");
    return fs::path(home && *home ? home : ".") / ".local" / "state" / "psc" / "play";
}

}  // namespace

ProgressStore::ProgressStore(const std::string& sourceSha1) : path_((stateDirectory() / (sourceSha1 + ".json")).string()) {}

Progress ProgressStore::load() {
    Progress progress;
    error_.clear();
    std::ifstream in(path_);
    if (!in) return progress;
    try {
        const nlohmann::json j = nlohmann::json::parse(in);
        for (const auto& level : j.at("solved")) progress.solved.insert(level.get<int>());
        progress.resumeEntry = j.value("resume_entry", -1);
    } catch (const std::exception& e) {
        error_ = "ignoring unreadable progress file " + path_;
        return Progress{};
    }
    return progress;
}

bool ProgressStore::save(const Progress& progress, const std::string& title) {
    error_.clear();
    nlohmann::ordered_json j;
    j["game"] = title;
    j["solved"] = progress.solved;
    j["resume_entry"] = progress.resumeEntry;
    std::error_code ec;
    fs::create_directories(fs::path(path_).parent_path(), ec);
    const std::string temporary = path_ + ".tmp";
    {
        std::ofstream out(temporary);
        out << j.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace) << "\n";
        if (!out.flush()) {
            error_ = "cannot save progress to " + path_;
            return false;
        }
    }
    fs::rename(temporary, path_, ec);
    if (ec) {
        error_ = "cannot save progress to " + path_ + ": " + ec.message();
        return false;
    }
    return true;
}

}  // namespace psc::play
