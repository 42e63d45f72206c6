// psc: the PuzzleScript compiler driver.
//
//   psc check GAME.txt                       diagnostics; exit 0 if the game compiles
//   psc GAME.txt --emit ast|ir|cpp [--format text|json|reference]
//   psc GAME.txt -o GAME.so                  build the step-function plugin
//   psc replay CASE.json                     replay a corpus trace and compare every state
//   psc play GAME.txt [--level N]            play the game in the terminal
//   psc --version                            the version, and whether CUDA plugins can be built
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>

#include "Bench.h"
#include "CppSource.h"
#include "Diagnose.h"
#include "GameBuild.h"
#include "Play.h"
#include "Replay.h"
#include "Solve.h"
#include "SourceFile.h"
#include "ast/AstDump.h"
#include "ir/IrDump.h"
#include "ir/ReferenceDump.h"
#include "base/Sha1.h"

namespace {

using namespace psc;

// CLI11's PositiveNumber and NonNegativeNumber name their range's upper bound
// in a rejection, which for a double is DBL_MAX's 309 digits.
CLI::Validator numberAbove(double low, bool orEqual) {
    const std::string wanted = orEqual ? "a number of 0 or more" : "a positive number";
    return CLI::Validator(
        [=](std::string& text) -> std::string {
            char* end = nullptr;
            const double value = std::strtod(text.c_str(), &end);
            const bool ok = end != text.c_str() && *end == '\0' && (orEqual ? value >= low : value > low);
            return ok ? std::string() : "must be " + wanted + ", not " + text;
        },
        orEqual ? "NONNEGATIVE" : "POSITIVE");
}

// With `cuda`, also checks that the game's generated CUDA source compiles
// (NVRTC's front end; no GPU needed).
int runCheck(const std::string& path, bool cuda) {
    auto source = cli::readSource(path);
    if (!source) return 1;
    CompileResult result = compileSource(*source);
    cli::printDiagnostics(stderr, path, result);
    if (result.status != CompileStatus::Ok) {
        fmt::print(stderr, "{}: {}\n", path, cli::verdict(result));
        return 1;
    }
    if (!cuda) return 0;
    cli::GameBuildOptions gb;
    gb.target = "cuda";
    gb.cuda.syntaxOnly = true;
    if (const std::string problem = cudaCompilerProblem(gb.cuda.compiler); !problem.empty()) {
        fmt::print(stderr, "{}: error: {}\n", path, problem);
        return 1;
    }
    const CudaCompileResult r = compileCuda(codegen::cudaSource(*result.game, cli::sourceOptions(*source, path, gb)), "check", gb.cuda);
    if (r.ok) return 0;
    fmt::print(stderr, "{}: error: the generated CUDA source does not compile\n{}\n", path, r.log);
    return 1;
}

int runEmit(const std::string& path, const std::string& stage, const std::string& format, bool keepGoing,
            const std::vector<int>& levels, const std::string& ruleForm) {
    auto source = cli::readSource(path);
    if (!source) return 1;
    if (stage == "cpp") {
        cli::GameBuildOptions gb;
        gb.keepGoing = keepGoing;
        gb.levels = levels;
        gb.target = "cpu";
        gb.ruleForm = ruleForm;
        auto game = cli::compileForBuild(*source, path, gb);
        if (!game) return 1;
        fmt::print("{}", codegen::cpuPluginSource(*game, cli::sourceOptions(*source, path, gb)));
        return 0;
    }
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

int runBuild(const std::string& path, const std::string& output, const cli::GameBuildOptions& options) {
    auto source = cli::readSource(path);
    if (!source) return 1;
    auto game = cli::compileForBuild(*source, path, options);
    if (!game) return 1;
    std::string built;
    auto plugin = cli::loadPlugin(*game, *source, path, options, &built);
    if (!plugin) return 1;
    std::error_code ec;
    std::filesystem::copy_file(built, output, std::filesystem::copy_options::overwrite_existing, ec);
    if (ec) {
        fmt::print(stderr, "{}: error: cannot write {}: {}\n", path, output, ec.message());
        return 1;
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"psc: compiles PuzzleScript games into step-function plugins"};
    app.require_subcommand(0, 1);
    app.set_version_flag("--version", std::function<std::string()>([] {
        const std::string cuda = cudaCompilerProblem("nvrtc");
        return fmt::format("psc {}\nCUDA plugins: {}", PSC_VERSION, cuda.empty() ? "NVRTC available" : cuda);
    }), "print the version, and whether CUDA plugins can be built, and exit");

    std::string game;
    std::string emit;
    std::string format = "text";
    bool keepGoing = false;
    app.add_option("game", game, "the PuzzleScript game to compile");
    std::string output;
    std::string target = cudaCompilerAvailable("nvrtc") ? "all" : "cpu";
    bool verbose = false;
    bool native = false;
    app.add_option("--emit", emit, "print one stage and stop")->check(CLI::IsMember({"ast", "ir", "cpp", "cuda", "ptx"}));
    app.add_option("-o,--output", output, "build the plugin (a shared library) to this file");
    std::string cudaCompiler = "nvrtc";
    std::string gpuState = "auto";
    int cudaArch = 90;
    app.add_option("--target", target, "plugin backends: cpu, or cuda/all (CUDA and CPU); default all when CUDA is available")
        ->check(CLI::IsMember({"cpu", "cuda", "all"}));
    app.add_option("--compiler", cudaCompiler, "CUDA compiler")->check(CLI::IsMember({"nvrtc", "nvcc"}));
    app.add_option("--arch", cudaArch, "CUDA architecture (90: sm_90, H100)");
    std::string fastCompile = CudaCompileOptions{}.fastCompile;
    const auto fastCompileLevels = CLI::IsMember({"0", "min", "mid", "max"});
    const char* fastCompileHelp = "CUDA -Ofast-compile level: 0 (full optimisation), min, mid, max";
    app.add_option("--fast-compile", fastCompile, fastCompileHelp)->check(fastCompileLevels);
    const auto gpuStates = CLI::IsMember({"auto", "registers", "memory", "groups", "shared"});
    const char* gpuStateHelp = "where the GPU keeps each environment's state";
    app.add_option("--gpu-state", gpuState, gpuStateHelp)->check(gpuStates);
    int cudaUnits = 0;
    const char* cudaUnitsHelp = "CUDA compile units NVRTC compiles at once (memory layout; from 3, one of them the turn's; the registers layout takes 2, or 1 for one program); 0: by code size";
    app.add_option("--cuda-units", cudaUnits, cudaUnitsHelp)->check(CLI::Range(0, 64));
    std::string ruleForm = "auto";
    const auto ruleForms = CLI::IsMember({"auto", "code", "table"});
    const char* ruleFormHelp =
        "rules as straight-line code (fastest steps), as a table an interpreter reads (compiles in seconds), "
        "or auto: code unless too large to compile in time";
    app.add_option("--rules", ruleForm, ruleFormHelp)->check(ruleForms);
    app.add_flag("--verbose", verbose, "print the compiler command and cache use");
    bool searchKernels = false;
    app.add_flag("--search-kernels", searchKernels, "also compile search's GPU expansion kernel (psc_expand on CUDA batches)");
    app.add_flag("--native", native, "optimise the CPU code for this machine (-march=native)");
    std::vector<int> buildLevels;
    app.add_option("--levels", buildLevels, "build only these playable levels (numbered from 0); smaller plugins step faster")
        ->delimiter(',');
    app.add_option("--format", format, "output format of --emit")->check(CLI::IsMember({"text", "json", "reference"}));
    app.add_flag("--keep-going", keepGoing, "build games that have errors but that the reference engine still plays");

    std::string checkGame;
    CLI::App* check = app.add_subcommand("check", "report errors and warnings; exit 0 when the game compiles");
    check->add_option("game", checkGame, "the game")->required();
    bool checkCuda = false;
    check->add_flag("--cuda", checkCuda, "also check that the game's generated CUDA source compiles");

    cli::ReplayOptions replayOptions;
    CLI::App* replay = app.add_subcommand("replay", "replay a corpus trace case and compare every state with it");
    replay->add_option("case", replayOptions.casePath, "the case file (JSON)")->required();
    replay->add_option("--backend", replayOptions.backend, "cpu")->check(CLI::IsMember({"cpu", "cuda"}));
    replay->add_option("--device", replayOptions.device, "CUDA device ordinal (--backend cuda)")->check(CLI::Range(0, 1023));
    replay->add_option("--fast-compile", replayOptions.build.cuda.fastCompile, fastCompileHelp)->check(fastCompileLevels);
    replay->add_option("--gpu-state", replayOptions.build.gpuState, gpuStateHelp)->check(gpuStates);
    replay->add_option("--rules", replayOptions.build.ruleForm, ruleFormHelp)->check(ruleForms);
    replay->add_option("--cuda-units", replayOptions.build.cudaUnits, cudaUnitsHelp)->check(CLI::Range(0, 64));
    replay->add_option("--dump", replayOptions.dumpPath, "write every state as a JSON line to this file");
    replay->add_flag("--check-keys", replayOptions.checkKeys, "also check that every level state's search key gives it back");
    replay->add_flag("--verbose", replayOptions.build.build.verbose, "print the compiler command and cache use");

    cli::BenchOptions benchOptions;
    CLI::App* bench = app.add_subcommand("bench", "steps per second on random actions (auto-reset on win)");
    bench->add_option("game", benchOptions.gamePath, "the game")->required();
    bench->add_option("--level", benchOptions.level, "playable level, from 0");
    bench->add_option("--batch", benchOptions.batches, "environments stepped together (a comma list sweeps)")->delimiter(',');
    bench->add_option("--steps", benchOptions.steps, "steps per environment in one timed run");
    bench->add_option("--threads", benchOptions.threads, "CPU threads");
    bench->add_option("--repeats", benchOptions.repeats, "timed runs (the median is reported)");
    bench->add_option("--warmup", benchOptions.warmup, "untimed runs first");
    bench->add_option("--time-limit", benchOptions.timeLimit, "seconds after which no further batch is begun (default 600)");
    bench->add_option("--backend", benchOptions.backend, "cpu")->check(CLI::IsMember({"cpu", "cuda"}));
    bench->add_option("--device", benchOptions.device, "CUDA device ordinal")->check(CLI::Range(0, 1023));
    bench->add_option("--devices", benchOptions.devices, "several CUDA devices (0,1,...): one batch each, stepped at once")
        ->delimiter(',')
        ->excludes("--device");
    bench->add_option("--fast-compile", benchOptions.build.cuda.fastCompile, fastCompileHelp)->check(fastCompileLevels);
    bench->add_option("--gpu-state", benchOptions.build.gpuState, gpuStateHelp)->check(gpuStates);
    bench->add_option("--rules", benchOptions.build.ruleForm, ruleFormHelp)->check(ruleForms);
    bench->add_option("--cuda-units", benchOptions.build.cudaUnits, cudaUnitsHelp)->check(CLI::Range(0, 64));
    bench->add_flag("--native", benchOptions.build.build.native, "compile for this machine (-march=native)");
    bench->add_flag("--expand", benchOptions.expand, "measure search's batched expansion (children/s) instead of steps/s");
    bench->add_flag("--all-levels", benchOptions.allLevels, "build the plugin for every level, not only the one measured");
    bench->add_flag("--verbose", benchOptions.build.build.verbose, "print the compiler command and cache use");

    cli::SolveCommandOptions solveOptions;
    CLI::App* solve = app.add_subcommand("solve", "find solutions of a game's levels by search (exit 0 when all are solved)");
    solve->add_option("game", solveOptions.gamePath, "the game")->required();
    solve->add_option("--level", solveOptions.levels, "playable levels, from 0 (a comma list); default 0")->delimiter(',');
    solve->add_flag("--all-levels", solveOptions.allLevels, "every playable level");
    solve->add_option("--algorithm", solveOptions.algorithm, "bfs (shortest), astar, wastar, greedy, beam, portfolio")
        ->check(CLI::IsMember({"bfs", "astar", "wastar", "greedy", "beam", "portfolio"}));
    solve->add_option("--backend", solveOptions.backend, "where states are expanded: cpu or cuda")
        ->check(CLI::IsMember({"cpu", "cuda"}));
    solve->add_option("--device", solveOptions.device, "CUDA device ordinal (--backend cuda)")->check(CLI::Range(0, 1023));
    solve->add_option("--threads", solveOptions.threads, "CPU threads expanding states")->check(numberAbove(0, false));
    solve->add_option("--time-limit", solveOptions.timeLimit, "seconds per level")->check(numberAbove(0, false));
    solve->add_option("--max-states", solveOptions.maxStates, "distinct states per level; 0: no limit but memory");
    solve->add_option("--max-memory", solveOptions.maxMemoryMb, "MB for the states of one search; 0: half the machine's memory (GPU breadth-first: nine tenths of the free device memory)")
        ->check(numberAbove(0, true));
    solve->add_option("--weight", solveOptions.weight, "wastar's weight on the estimate (>= 1)");
    solve->add_option("--beam-width", solveOptions.beamWidth, "states beam search keeps a layer; 0: from 256 (CPU) or 4,096 (GPU), four times wider each time a beam empties, to 10,000 (CPU) or 16,777,216 (GPU)");
    solve->add_option("--seed", solveOptions.seed, "the level's random seed (games that use random)");
    solve->add_option("--from-inputs", solveOptions.fromInputs, "inputs (u d l r x) played before searching");
    solve->add_option("--format", solveOptions.format, "text, or json: one object per level and line")
        ->check(CLI::IsMember({"text", "json"}));
    solve->add_flag("--quiet", solveOptions.quiet, "no progress line");
    solve->add_flag("--keep-going", solveOptions.build.keepGoing, "search games that have errors but that the reference engine still plays");
    solve->add_option("--fast-compile", solveOptions.build.cuda.fastCompile, fastCompileHelp)->check(fastCompileLevels);
    solve->add_option("--gpu-state", solveOptions.build.gpuState, gpuStateHelp)->check(gpuStates);
    solve->add_option("--rules", solveOptions.build.ruleForm, ruleFormHelp)->check(ruleForms);
    solve->add_flag("--verbose", solveOptions.build.build.verbose, "print the compiler command and cache use");

    cli::PlayCommandOptions playOptions;
    CLI::App* play = app.add_subcommand("play", "play the game in the terminal (arrows or WASD, X action, Z undo, R restart, Q quit)");
    play->add_option("game", playOptions.gamePath, "the game")->required();
    play->add_option("--level", playOptions.level, "start at this playable level (from 0) instead of the title screen");
    play->add_flag("--glyphs", playOptions.glyphs, "draw levels with their legend glyphs, not sprites");
    play->add_flag("--scripted", playOptions.scripted,
                   "read keys from standard input (a pipe is fine); without a terminal, print what happens");
    play->add_option("--replay", playOptions.replay, "animate these inputs first: u l d r x, z undo, ! restart, . tick");
    play->add_option("--replay-file", playOptions.replayFile, "animate the inputs in this file first (as --record writes)");
    play->add_option("--replay-interval", playOptions.replayInterval, "seconds between replayed inputs")
        ->check(CLI::Range(0.0, 10.0));
    play->add_option("--record", playOptions.recordPath, "write the inputs played to this file");
    play->add_option("--seed", playOptions.seed, "the random seed of games that use random (default: from the clock)");
    play->add_option("--hint-time-limit", playOptions.hintTimeLimit, "seconds the hint key's search may take")
        ->check(CLI::Range(0.1, 3600.0));

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        // Bad arguments exit 2 (psc solve promises 0/1 for solved or not).
        const int status = app.exit(e);
        return status == 0 ? 0 : 2;
    }

    if (*play) return cli::runPlay(playOptions);
    if (*bench) return cli::runBench(benchOptions);
    if (*solve) return cli::runSolve(solveOptions);
    if (*check) return runCheck(checkGame, checkCuda);
    if (*replay) return cli::runReplay(replayOptions);
    if (game.empty()) {
        fmt::print(stderr, "{}", app.help());
        return 2;
    }
    if (emit.empty() && output.empty()) {
        fmt::print(stderr, "psc: nothing to do (use -o, --emit, or a subcommand)\n");
        return 2;
    }
    if (!output.empty()) {
        cli::GameBuildOptions options;
        options.keepGoing = keepGoing;
        options.build.verbose = verbose;
        options.build.native = native;
        options.levels = buildLevels;
        options.target = target;
        options.cuda.compiler = cudaCompiler;
        options.cuda.architecture = cudaArch;
        options.cuda.fastCompile = fastCompile;
        options.cuda.verbose = verbose;
        options.gpuState = gpuState;
        options.cudaUnits = cudaUnits;
        options.searchKernels = searchKernels;
        options.ruleForm = ruleForm;
        return runBuild(game, output, options);
    }
    if (format == "reference" && emit != "ir") {
        fmt::print(stderr, "psc: --format reference applies to --emit ir\n");
        return 2;
    }
    if (emit == "cuda" || emit == "ptx") {
        auto source = cli::readSource(game);
        if (!source) return 1;
        cli::GameBuildOptions gb;
        gb.keepGoing = keepGoing;
        gb.levels = buildLevels;
        gb.target = "cuda";
        gb.cuda.compiler = cudaCompiler;
        gb.cuda.architecture = cudaArch;
        gb.cuda.fastCompile = fastCompile;
        gb.build.verbose = verbose;
        gb.gpuState = gpuState;
        gb.cudaUnits = cudaUnits;
        gb.searchKernels = searchKernels;
        gb.ruleForm = ruleForm;
        auto compiled = cli::compileForBuild(*source, game, gb);
        if (!compiled) return 1;
        if (emit == "cuda") {
            fmt::print("{}", codegen::cudaSource(*compiled, cli::sourceOptions(*source, game, gb)));
            return 0;
        }
        auto device = cli::compileDeviceCode(*compiled, *source, game, gb);
        if (!device) return 1;
        for (size_t k = 0; k < device->ptx.size(); ++k) {
            if (device->ptx.size() > 1) fmt::print("// ---- compile unit {} of {}\n", k, device->ptx.size());
            fmt::print("{}", device->ptx[k]);
        }
        return 0;
    }
    return runEmit(game, emit, format, keepGoing, buildLevels, ruleForm);
}
