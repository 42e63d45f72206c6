// psc play: plays a game in the terminal (play/Player.h).
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace psc::cli {

struct PlayCommandOptions {
    std::string gamePath;
    std::optional<int> level;  // playable, from 0
    bool glyphs = false;
    bool scripted = false;
    std::string replay;
    std::string replayFile;
    double replayInterval = 0.15;
    std::string recordPath;
    std::optional<uint64_t> seed;
    double hintTimeLimit = 10;
};

int runPlay(const PlayCommandOptions& options);

}  // namespace psc::cli
