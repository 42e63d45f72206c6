#include "Player.h"

#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <fmt/format.h>
#include <fstream>
#include <memory>
#include <stdexcept>

#include "Canvas.h"
#include "Hint.h"
#include "InputScript.h"
#include "Keys.h"
#include "Progress.h"
#include "Screens.h"
#include "Session.h"
#include "Terminal.h"

namespace psc::play {
namespace {

using Clock = std::chrono::steady_clock;

// How long a lone Esc waits for the rest of an escape sequence.
constexpr auto kEscapeWait = std::chrono::milliseconds(30);

enum class Mode { Title, Game, LevelSelect };

Clock::duration seconds(double s) { return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s)); }

const char* inputName(char letter) {
    switch (letter) {
        case 'u': return "up";
        case 'l': return "left";
        case 'd': return "down";
        case 'r': return "right";
        case 'x': return "action";
        default: return "?";
    }
}

const char* arrowOf(char letter) {
    switch (letter) {
        case 'u': return "\u2191";
        case 'l': return "\u2190";
        case 'd': return "\u2193";
        case 'r': return "\u2192";
        default: return "X";
    }
}

class Player {
public:
    Player(const Plugin& plugin, const GameDisplay& display, const PlayOptions& options);
    int run();

private:
    // Input.
    void handleKey(Key key);
    void titleKey(Key key);
    void levelSelectKey(Key key);
    void gameKey(Key key);
    void apply(int action);  // one game input, recorded
    void runAgainTurn();     // the `again` turn due (not an input: not recorded)
    void settleAgain();      // every `again` turn due at once (--scripted)
    void afterTurn(const StepReport& report);
    bool againDue() const { return mode_ == Mode::Game && session_.againing() && !ruleMessage_; }
    void closeMessage();
    void closeRuleMessage();
    // Moving around.
    void startEntry(int entry);
    void startLevel(int level);
    void openTitle(const std::string& note);
    void openLevelSelect();
    void completeGame();
    void quit(int status) {
        quitStatus_ = status;
        quitting_ = true;
    }
    // Hints.
    void requestHint();
    void showHint(const HintAnswer& answer);
    // Replays.
    void replayNext();
    // Output.
    void render();
    void logScreen();
    void logLine(const std::string& line);
    void printFinalState();
    std::string statusLeft() const;
    std::string helpLine() const;
    std::vector<std::string> titleChoices() const;
    void saveProgress();
    bool flag(uint32_t f) const { return (session_.info().flags & f) != 0; }
    bool realtimeActive() const;
    // Ticks run on through inputs, as in the reference's front end.
    Clock::duration tickInterval() const { return seconds(info_.realtime_interval); }
    Clock::duration againInterval() const { return seconds(info_.again_interval); }

    int runInteractive();
    int runScripted();

    const PlayOptions& options_;
    const psc_game_info& info_;
    Session session_;
    LevelView view_;
    ProgressStore store_;
    Progress progress_;
    HintSearch hint_;
    std::unique_ptr<Terminal> terminal_;
    std::ofstream record_;
    KeyDecoder decoder_;
    ColorMode colors_;
    Theme theme_;
    bool logMode_;

    Mode mode_ = Mode::Title;
    Mode beforeSelect_ = Mode::Title;
    int titleSelected_ = 0;
    std::string titleNote_;
    int selectCursor_ = 0;
    int selectPerRow_ = 1;
    std::string note_;
    std::string lastLogged_;
    std::optional<std::pair<int, std::string>> hintFor_;  // (entry, inputs) the running search is for

    size_t replayAt_ = 0;
    bool replaying_ = false;
    Clock::time_point nextReplay_;
    Clock::time_point nextTick_;
    Clock::time_point nextAgain_;
    // A rule's message, shown over the level until X; again turns wait for it.
    std::optional<std::string> ruleMessage_;
    bool completeAfterMessage_ = false;  // the turn that showed it completed the game

    bool quitting_ = false;
    int quitStatus_ = 0;
};

Player::Player(const Plugin& plugin, const GameDisplay& display, const PlayOptions& options)
    : options_(options),
      info_(plugin.info()),
      session_(plugin, options.seed),
      view_(display, plugin.info()),
      store_(plugin.info().source_sha1),
      colors_(detectColorMode()),
      logMode_(options.scripted && !isatty(STDOUT_FILENO)) {
    theme_.background = info_.background_color;
    theme_.text = info_.text_color;
    progress_ = store_.load();
    if (!store_.error().empty()) note_ = store_.error();
    if (!options.recordPath.empty()) {
        record_.open(options.recordPath);
        if (!record_) throw std::runtime_error("cannot write the record " + options.recordPath);
        record_ << "# psc play " << options.gamePath << " --seed " << options.seed
                << (options.level ? " --level " + std::to_string(*options.level) : std::string()) << "\n";
        record_.flush();
    }
    terminal_ = std::make_unique<Terminal>(STDIN_FILENO, STDOUT_FILENO, !logMode_);
}

// ---- moving around

void Player::startEntry(int entry) {
    hint_.cancel();
    hintFor_.reset();
    ruleMessage_.reset();
    completeAfterMessage_ = false;
    session_.startEntry(entry);
    view_.resetCamera();
    mode_ = Mode::Game;
    nextTick_ = Clock::now() + tickInterval();
    saveProgress();
}

void Player::startLevel(int level) {
    if (!info_.level_built[level]) {
        note_ = fmt::format("level {} is not in this build of the game", level + 1);
        return;
    }
    if (record_.is_open() && !replaying_) {
        record_ << "\n# level " << level << "\n";
        record_.flush();
    }
    startEntry(info_.level_entries[level]);
}

void Player::openTitle(const std::string& note) {
    hint_.cancel();
    hintFor_.reset();
    ruleMessage_.reset();
    completeAfterMessage_ = false;
    mode_ = Mode::Title;
    titleSelected_ = 0;
    titleNote_ = note;
}

void Player::openLevelSelect() {
    beforeSelect_ = mode_;
    mode_ = Mode::LevelSelect;
    int level = session_.level();
    if (level < 0) level = session_.levelAtOrAfter(session_.entry());
    if (level < 0 && progress_.resumeEntry >= 0) level = session_.levelAtOrAfter(progress_.resumeEntry);
    selectCursor_ = std::max(level, 0);
}

void Player::completeGame() {
    progress_.resumeEntry = -1;
    store_.save(progress_, info_.title);
    logLine("game completed");
    openTitle(fmt::format("Congratulations: you completed the game ({} of {} levels solved).", progress_.solved.size(),
                          info_.level_count));
}

void Player::saveProgress() {
    if (mode_ == Mode::Game) progress_.resumeEntry = session_.entry();
    if (!store_.save(progress_, info_.title)) note_ = store_.error();
}

std::vector<std::string> Player::titleChoices() const {
    if (progress_.resumeEntry > 0 && progress_.resumeEntry < info_.entry_count) {
        const int level = session_.levelAtOrAfter(progress_.resumeEntry);
        return {level >= 0 ? fmt::format("continue from level {}", level + 1) : "continue", "new game"};
    }
    return {"start game"};
}

// ---- input

void Player::handleKey(Key key) {
    if (key == Key::Interrupt) return quit(130);
    if (key == Key::Quit) return quit(0);
    if (replaying_) {
        replaying_ = false;
        note_ = "replay stopped";
        return;
    }
    note_.clear();
    switch (mode_) {
        case Mode::Title: titleKey(key); break;
        case Mode::LevelSelect: levelSelectKey(key); break;
        case Mode::Game: gameKey(key); break;
    }
}

void Player::titleKey(Key key) {
    const int choices = static_cast<int>(titleChoices().size());
    switch (key) {
        case Key::Up: case Key::Left: titleSelected_ = (titleSelected_ + choices - 1) % choices; break;
        case Key::Down: case Key::Right: titleSelected_ = (titleSelected_ + 1) % choices; break;
        case Key::Action:
            if (choices > 1 && titleSelected_ == 0) startEntry(progress_.resumeEntry);
            else startEntry(0);
            break;
        case Key::LevelSelect: openLevelSelect(); break;
        default: break;
    }
}

void Player::levelSelectKey(Key key) {
    const int count = info_.level_count;
    switch (key) {
        case Key::Left: selectCursor_ = std::max(0, selectCursor_ - 1); break;
        case Key::Right: selectCursor_ = std::min(count - 1, selectCursor_ + 1); break;
        case Key::Up: if (selectCursor_ >= selectPerRow_) selectCursor_ -= selectPerRow_; break;
        case Key::Down: if (selectCursor_ + selectPerRow_ < count) selectCursor_ += selectPerRow_; break;
        case Key::Action: startLevel(selectCursor_); break;
        case Key::Back: case Key::LevelSelect: mode_ = beforeSelect_; break;
        default: break;
    }
}

void Player::gameKey(Key key) {
    if (ruleMessage_) {
        switch (key) {
            case Key::Action: return closeRuleMessage();
            case Key::Back: case Key::NextLevel: case Key::PreviousLevel: case Key::LevelSelect: break;
            default: return;
        }
    }
    const bool onLevel = session_.screen() == Screen::Level;
    const int level = onLevel ? session_.level() : session_.levelAtOrAfter(session_.entry());
    switch (key) {
        case Key::Up: case Key::Left: case Key::Down: case Key::Right:
            if (onLevel) apply(key == Key::Up ? PSC_ACTION_UP : key == Key::Left ? PSC_ACTION_LEFT
                               : key == Key::Down ? PSC_ACTION_DOWN : PSC_ACTION_RIGHT);
            break;
        case Key::Action:
            if (!onLevel) closeMessage();
            else if (flag(PSC_FLAG_NOACTION)) note_ = "this game has no action key (noaction)";
            else apply(PSC_ACTION_ACTION);
            break;
        case Key::Undo:
            if (!onLevel) break;
            if (flag(PSC_FLAG_NOUNDO)) note_ = "undo is off in this game (noundo)";
            else apply(PSC_ACTION_UNDO);
            break;
        case Key::Restart:
            if (!onLevel) break;
            if (flag(PSC_FLAG_NORESTART)) note_ = "restart is off in this game (norestart)";
            else apply(PSC_ACTION_RESTART);
            break;
        case Key::Back: openTitle(""); break;
        case Key::NextLevel: {
            const int next = onLevel ? level + 1 : level;
            if (next >= 0 && next < info_.level_count) startLevel(next);
            else note_ = "this is the last level";
            break;
        }
        case Key::PreviousLevel: {
            const int previous = (onLevel ? level : (level < 0 ? info_.level_count : level)) - 1;
            if (previous >= 0) startLevel(previous);
            else note_ = "this is the first level";
            break;
        }
        case Key::LevelSelect: openLevelSelect(); break;
        case Key::Hint: requestHint(); break;
        default: break;
    }
}

void Player::apply(int action) {
    if (mode_ != Mode::Game) return;
    if (session_.screen() != Screen::Level) {
        if (action == PSC_ACTION_ACTION) closeMessage();
        return;
    }
    // The reference's player drops inputs while an `again` chain runs.
    if (session_.againing() && action != PSC_ACTION_UNDO && action != PSC_ACTION_RESTART) return;
    if (hint_.running()) {
        hint_.cancel();
        hintFor_.reset();
        note_ = "hint cancelled";
    }
    if (record_.is_open()) {
        record_ << inputLetter(action);
        record_.flush();
    }
    const StepReport report = session_.step(action);
    if (action == PSC_ACTION_TICK) nextTick_ = Clock::now() + tickInterval();
    afterTurn(report);
}

void Player::runAgainTurn() { afterTurn(session_.step(PSC_ACTION_TICK)); }

void Player::settleAgain() {
    while (againDue() && !quitting_) {
        runAgainTurn();
        render();
    }
}

void Player::afterTurn(const StepReport& report) {
    if (report.againing) nextAgain_ = Clock::now() + againInterval();
    if (report.cutOff) note_ = "an endless `again` chain was cut off";
    if (!report.message.empty()) {
        ruleMessage_ = report.message;
        logScreen();  // before the win, which the reference checks when the message closes
    }
    if (report.won) {
        progress_.solved.insert(report.wonLevel);
        view_.resetCamera();
        logLine(fmt::format("solved level {}", report.wonLevel + 1));
        if (report.completed) {
            if (!ruleMessage_) return completeGame();
            completeAfterMessage_ = true;
            return;
        }
        note_ = fmt::format("level {} solved", report.wonLevel + 1);
        saveProgress();
    }
}

void Player::closeRuleMessage() {
    ruleMessage_.reset();
    nextAgain_ = Clock::now() + againInterval();
    if (completeAfterMessage_) {
        completeAfterMessage_ = false;
        completeGame();
    }
}

void Player::closeMessage() {
    if (record_.is_open()) {
        record_ << 'x';
        record_.flush();
    }
    const int next = session_.entry() + 1;
    if (next < info_.entry_count) startEntry(next);
    else completeGame();
}

// ---- hints

void Player::requestHint() {
    if (session_.screen() != Screen::Level || ruleMessage_ || session_.againing()) return;
    if (flag(PSC_FLAG_REALTIME)) {
        note_ = "no hints in realtime games: the solver does not play the clock's ticks";
        return;
    }
    if (!session_.path()) {
        note_ = "no hint here: after undo, this game's random stream is where no inputs lead; restart the level";
        return;
    }
    HintRequest request;
    request.pscBinary = options_.pscBinary;
    request.gamePath = options_.gamePath;
    request.level = session_.level();
    request.fromInputs = *session_.path();
    request.seed = options_.seed;
    request.timeLimit = options_.hintTimeLimit;
    std::string problem;
    if (!hint_.start(request, &problem)) {
        note_ = "no hint: " + problem;
        return;
    }
    hintFor_ = std::make_pair(session_.entry(), *session_.path());
    note_ = "hint: searching...";
    if (options_.scripted) {
        if (auto answer = hint_.collect(true)) showHint(*answer);
    }
}

void Player::showHint(const HintAnswer& answer) {
    const bool current = hintFor_ && hintFor_->first == session_.entry() && session_.path() && hintFor_->second == *session_.path();
    hintFor_.reset();
    if (!current) return;
    if (answer.solved) {
        note_ = fmt::format("hint: {} ({}), {} input{} to win", arrowOf(answer.nextInput), inputName(answer.nextInput),
                            answer.remaining, answer.remaining == 1 ? "" : "s");
    } else {
        note_ = "no hint: " + answer.problem;
    }
    logLine(note_);
}

// ---- replays

void Player::replayNext() {
    if (replayAt_ >= options_.replay.size()) {
        if (replaying_) note_ = "replay finished";
        replaying_ = false;
        return;
    }
    // A replay waits for the `again` chain and shows a rule's message for one interval.
    if (mode_ == Mode::Game && ruleMessage_) return closeRuleMessage();
    if (againDue()) return;
    const int action = options_.replay[replayAt_++];
    if (mode_ == Mode::Game) {
        if (session_.screen() != Screen::Level && action == PSC_ACTION_ACTION) closeMessage();
        else if (session_.screen() == Screen::Level) apply(action);
    }
    if (replayAt_ >= options_.replay.size()) {
        replaying_ = false;
        note_ = fmt::format("replay finished ({} inputs)", options_.replay.size());
    }
}

// ---- output

bool Player::realtimeActive() const {
    return info_.realtime_interval > 0 && mode_ == Mode::Game && session_.screen() == Screen::Level && !replaying_ &&
           !session_.againing() && !ruleMessage_;
}

std::string Player::statusLeft() const {
    std::string title = info_.title && *info_.title ? info_.title : "(untitled)";
    if (mode_ == Mode::Title) return title;
    if (mode_ == Mode::LevelSelect) return title + " \u00b7 level select";
    if (ruleMessage_) return title + " \u00b7 message";
    if (session_.screen() == Screen::Message) {
        const int next = session_.levelAtOrAfter(session_.entry());
        return title + (next >= 0 ? fmt::format(" \u00b7 before level {} of {}", next + 1, info_.level_count) : " \u00b7 the end");
    }
    const int level = session_.level();
    std::string s = fmt::format("{} \u00b7 level {} of {} \u00b7 moves {}", title, level + 1, info_.level_count, session_.moves());
    if (progress_.solved.count(level)) s += " \u00b7 solved before";
    return s;
}

std::string Player::helpLine() const {
    if (mode_ == Mode::Title) return "Q quit \u00b7 arrows select \u00b7 X start \u00b7 L level select";
    if (mode_ == Mode::LevelSelect) return "Q quit \u00b7 arrows move \u00b7 X play \u00b7 Esc back";
    if (ruleMessage_) return "Q quit \u00b7 X continue";
    if (session_.screen() == Screen::Message) return "Q quit \u00b7 X continue \u00b7 L levels \u00b7 N/P next/previous \u00b7 Esc title";
    std::string s = "Q quit \u00b7 arrows/WASD move";
    if (!flag(PSC_FLAG_NOACTION)) s += " \u00b7 X act";
    if (!flag(PSC_FLAG_NOUNDO)) s += " \u00b7 Z undo";
    if (!flag(PSC_FLAG_NORESTART)) s += " \u00b7 R restart";
    return s + " \u00b7 H hint \u00b7 L levels \u00b7 N/P next/previous \u00b7 Esc title";
}

void Player::render() {
    logScreen();
    if (logMode_) return;
    const TerminalSize size = terminal_->size();
    Canvas canvas(size.columns, size.rows);
    const Area area{0, 1, size.columns, std::max(0, size.rows - 2)};
    switch (mode_) {
        case Mode::Title: {
            TitleScreen t;
            t.title = info_.title ? info_.title : "";
            t.author = info_.author ? info_.author : "";
            t.homepage = info_.homepage ? info_.homepage : "";
            t.choices = titleChoices();
            t.selected = titleSelected_;
            t.note = titleNote_;
            drawTitle(canvas, area, t, theme_);
            break;
        }
        case Mode::LevelSelect:
            selectPerRow_ = drawLevelSelect(canvas, area, LevelSelectScreen{info_.level_count, progress_.solved, selectCursor_});
            break;
        case Mode::Game:
            if (ruleMessage_) {
                drawMessage(canvas, area, *ruleMessage_, theme_);
            } else if (session_.screen() == Screen::Level) {
                const LevelStyle style = view_.choose(session_, area, options_.forceGlyphs, colors_);
                view_.draw(canvas, session_, area, style, colors_);
            } else {
                drawMessage(canvas, area, session_.message(), theme_);
            }
            break;
    }
    std::string right;
    if (replaying_) right = fmt::format("replay {}/{}", replayAt_, options_.replay.size());
    drawBar(canvas, 0, statusLeft(), right);
    if (size.rows > 1) drawLine(canvas, size.rows - 1, note_.empty() ? helpLine() : note_, !note_.empty());
    terminal_->write(canvas.ansi(colors_));
}

// In --scripted mode without a terminal: one line per screen shown.
void Player::logScreen() {
    if (!logMode_) return;
    std::string line;
    if (mode_ == Mode::Title) line = "title: " + std::string(info_.title ? info_.title : "");
    else if (mode_ == Mode::LevelSelect) line = "level select";
    else if (ruleMessage_) line = "message: " + *ruleMessage_;
    else if (session_.screen() == Screen::Message) line = "message: " + session_.message();
    else line = fmt::format("level {} of {}", session_.level() + 1, info_.level_count);
    if (line != lastLogged_) logLine(line);
    lastLogged_ = line;
}

void Player::logLine(const std::string& line) {
    if (!logMode_) return;
    std::fputs((line + "\n").c_str(), stdout);
    std::fflush(stdout);
}

void Player::printFinalState() {
    if (!logMode_) return;
    logLine(statusLeft());
    if (mode_ != Mode::Game || session_.screen() != Screen::Level || ruleMessage_) return;
    // The level as a terminal of 100 x 50 would show it, without the blank rows around it.
    Canvas canvas(100, std::min(session_.height(), 48) + 2);
    view_.draw(canvas, session_, Area{0, 0, canvas.columns(), canvas.rows()}, LevelStyle::Glyphs, ColorMode::None);
    std::vector<std::string> rows = canvas.plainRows();
    while (!rows.empty() && rows.back().empty()) rows.pop_back();
    size_t first = 0;
    while (first < rows.size() && rows[first].empty()) ++first;
    for (size_t i = first; i < rows.size(); ++i) logLine(rows[i]);
}

// ---- the loops

int Player::run() {
    if (options_.level) {
        startLevel(*options_.level);
    } else if (options_.hasReplay) {
        startLevel(0);
    }
    replaying_ = options_.hasReplay && !options_.replay.empty();
    return options_.scripted ? runScripted() : runInteractive();
}

int Player::runScripted() {
    render();
    while (replaying_) {
        replayNext();
        render();
        settleAgain();
    }
    char buffer[4096];
    while (!quitting_) {
        const ssize_t n = read(STDIN_FILENO, buffer, sizeof buffer);
        const TerminalEvents events = terminal_->takeEvents();
        if (events.stopSignal) return 128 + events.stopSignal;
        if (n < 0 && errno == EINTR) continue;
        const bool ended = n <= 0;
        if (!ended) decoder_.feed(buffer, static_cast<size_t>(n));
        while (!quitting_) {
            const std::optional<Key> key = decoder_.next(ended);
            if (!key) break;
            handleKey(*key);
            render();
            settleAgain();
        }
        if (ended) break;
    }
    printFinalState();
    return quitStatus_;
}

int Player::runInteractive() {
    render();
    nextReplay_ = Clock::now() + seconds(options_.replayInterval);
    Clock::time_point lastByte = Clock::now();
    bool inputOpen = true;
    while (!quitting_) {
        const Clock::time_point now = Clock::now();
        std::optional<Clock::time_point> wake;
        auto wakeAt = [&](Clock::time_point t) { wake = wake ? std::min(*wake, t) : t; };
        if (replaying_) wakeAt(nextReplay_);
        if (realtimeActive()) wakeAt(nextTick_);
        if (againDue()) wakeAt(nextAgain_);
        if (decoder_.waiting()) wakeAt(lastByte + kEscapeWait);
        int timeout = -1;
        if (wake) timeout = static_cast<int>(std::max<long long>(0, std::chrono::duration_cast<std::chrono::milliseconds>(*wake - now).count() + 1));
        pollfd fds[3] = {{terminal_->eventFd(), POLLIN, 0}, {inputOpen ? STDIN_FILENO : -1, POLLIN, 0}, {hint_.fd(), POLLIN, 0}};
        const int ready = poll(fds, 3, timeout);
        if (ready < 0 && errno != EINTR) throw std::runtime_error("poll failed");
        const TerminalEvents events = terminal_->takeEvents();
        if (events.stopSignal) return 128 + events.stopSignal;
        bool dirty = events.resized;
        if (ready > 0 && (fds[1].revents & (POLLIN | POLLHUP | POLLERR))) {
            char buffer[1024];
            const ssize_t n = read(STDIN_FILENO, buffer, sizeof buffer);
            if (n > 0) {
                decoder_.feed(buffer, static_cast<size_t>(n));
                lastByte = Clock::now();
            } else if (n == 0 || (errno != EAGAIN && errno != EINTR)) {
                inputOpen = false;  // the terminal went away
                quit(0);
            }
        }
        const bool idle = Clock::now() - lastByte >= kEscapeWait;
        while (!quitting_) {
            const std::optional<Key> key = decoder_.next(idle);
            if (!key) break;
            handleKey(*key);
            dirty = true;
        }
        if (ready > 0 && hint_.running() && (fds[2].revents & (POLLIN | POLLHUP | POLLERR))) {
            if (auto answer = hint_.collect(false)) {
                showHint(*answer);
                dirty = true;
            }
        }
        if (replaying_ && Clock::now() >= nextReplay_) {
            replayNext();
            nextReplay_ += seconds(options_.replayInterval);
            dirty = true;
        }
        if (againDue() && Clock::now() >= nextAgain_) {
            runAgainTurn();
            dirty = true;
        }
        if (realtimeActive() && Clock::now() >= nextTick_) {
            apply(PSC_ACTION_TICK);
            dirty = true;
        }
        if (dirty && !quitting_) render();
    }
    return quitStatus_;
}

}  // namespace

int play(const Plugin& plugin, const GameDisplay& display, const PlayOptions& options) {
    Player player(plugin, display, options);
    return player.run();
}

}  // namespace psc::play
