// Progress per game, kept between runs: the levels solved and where to
// resume.  One JSON file per game, named by the sha1 of its text, under
// $XDG_STATE_HOME/psc/play (default ~/.local/state/psc/play).
#pragma once

#include <set>
#include <string>

namespace psc::play {

struct Progress {
    std::set<int> solved;  // playable levels, from 0
    int resumeEntry = -1;  // the LEVELS entry to continue at; -1: start at the beginning
};

class ProgressStore {
public:
    // The store of the game whose text has this sha1.
    explicit ProgressStore(const std::string& sourceSha1);
    const std::string& path() const { return path_; }
    // What was saved; nothing saved (or an unreadable file) is no progress, and error() says why.
    Progress load();
    // Writes atomically; false (and error()) when it cannot.
    bool save(const Progress& progress, const std::string& title);
    const std::string& error() const { return error_; }

private:
    std::string path_;
    std::string error_;
};

}  // namespace psc::play
