// psc: the PuzzleScript compiler driver.
//
//   psc check GAME.txt                       diagnostics; exit 0 if the game compiles
//   psc GAME.txt --emit ast|ir [--format text|json|reference]
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <cstdio>

#include "Diagnose.h"
#include "SourceFile.h"
#include "ast/AstDump.h"
#include "ir/IrDump.h"
#include "ir/ReferenceDump.h"
#include "base/Sha1.h"

namespace {

using namespace psc;

int runCheck(const std::string& path) {
    auto source = cli::readSource(path);
    if (!source) return 1;
    CompileResult result = compileSource(*source);
    cli::printDiagnostics(stderr, path, result);
    if (result.status == CompileStatus::Ok) return 0;
    fmt::print(stderr, "{}: {}\n", path, cli::verdict(result));
    return 1;
}

int runEmit(const std::string& path, const std::string& stage, const std::string& format, bool keepGoing) {
    auto source = cli::readSource(path);
    if (!source) return 1;
    if (stage == "ast") {
        CompileResult parsed = parseSource(*source);
        cli::printDiagnostics(stderr, path, parsed);
        if (!parsed.ast) return 1;
        if (format == "json") fmt::print("{}\n", ast::dumpJson(*parsed.ast).dump(2));
        else fmt::print("{}", ast::dumpText(*parsed.ast));
        return parsed.status == CompileStatus::Ok || keepGoing ? 0 : 1;
    }
    CompileResult result = compileSource(*source);
    cli::printDiagnostics(stderr, path, result);
    bool usable = result.status == CompileStatus::Ok || (keepGoing && result.game);
    if (!usable) {
        fmt::print(stderr, "{}: {}\n", path, cli::verdict(result));
        return 1;
    }
    const std::string sha1 = sha1Hex(*source);
    if (format == "reference") fmt::print("{}", ir::referenceDumpText(*result.game, sha1));
    else if (format == "json") fmt::print("{}\n", ir::dumpJson(*result.game, sha1).dump(2));
    else fmt::print("{}", ir::dumpText(*result.game, path));
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"psc: compiles PuzzleScript games into step-function plugins"};
    app.require_subcommand(0, 1);

    std::string game;
    std::string emit;
    std::string format = "text";
    bool keepGoing = false;
    app.add_option("game", game, "the PuzzleScript game to compile");
    app.add_option("--emit", emit, "print one stage and stop")->check(CLI::IsMember({"ast", "ir"}));
    app.add_option("--format", format, "output format of --emit")->check(CLI::IsMember({"text", "json", "reference"}));
    app.add_flag("--keep-going", keepGoing, "build games that have errors but that the reference engine still plays");

    std::string checkGame;
    CLI::App* check = app.add_subcommand("check", "report errors and warnings; exit 0 when the game compiles");
    check->add_option("game", checkGame, "the game")->required();

    CLI11_PARSE(app, argc, argv);

    if (*check) return runCheck(checkGame);
    if (game.empty()) {
        fmt::print(stderr, "{}", app.help());
        return 2;
    }
    if (emit.empty()) {
        fmt::print(stderr, "psc: nothing to do (use --emit, or check)\n");
        return 2;
    }
    if (format == "reference" && emit != "ir") {
        fmt::print(stderr, "psc: --format reference applies to --emit ir\n");
        return 2;
    }
    return runEmit(game, emit, format, keepGoing);
}
