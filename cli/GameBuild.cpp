#include "GameBuild.h"

#include <fmt/format.h>

#include "CppSource.h"
#include "Diagnose.h"
#include "base/Sha1.h"

namespace psc::cli {

std::optional<ir::Game> compileForBuild(const std::string& text, const std::string& path, const GameBuildOptions& options) {
    CompileResult result = compileSource(text);
    if (!options.quiet) printDiagnostics(stderr, path, result);
    const bool usable = result.status == CompileStatus::Ok || (options.keepGoing && result.status == CompileStatus::Playable);
    if (!usable) {
        fmt::print(stderr, "{}: {}\n", path, verdict(result));
        return std::nullopt;
    }
    return std::move(result.game);
}

std::unique_ptr<Plugin> loadCpuPlugin(const ir::Game& game, const std::string& text, const std::string& path,
                                      const GameBuildOptions& options, std::string* pluginPath) {
    codegen::SourceOptions so;
    so.sourceName = path;
    so.sourceSha1 = sha1Hex(text);
    so.levels = options.levels;
    const std::string source = codegen::cpuPluginSource(game, so);
    BuildResult built = buildCpuPlugin(source, options.build);
    if (!built.ok) {
        fmt::print(stderr, "{}: error: building the plugin failed\n{}\n{}\n", path, built.command, built.log);
        return nullptr;
    }
    if (options.build.verbose) {
        fmt::print(stderr, "psc: plugin {} ({})\n", built.pluginPath,
                   built.cached ? "from the cache" : fmt::format("built in {:.2f} s", built.seconds));
    }
    std::string error;
    auto plugin = Plugin::open(built.pluginPath, &error);
    if (!plugin) fmt::print(stderr, "{}: error: {}\n", path, error);
    if (pluginPath) *pluginPath = built.pluginPath;
    return plugin;
}

}  // namespace psc::cli
