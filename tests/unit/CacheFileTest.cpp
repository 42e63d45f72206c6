#include <catch2/catch.hpp>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "CacheFile.h"

namespace fs = std::filesystem;

TEST_CASE("cache files: writers racing on one path all succeed and leave it whole", "[runtime]") {
    const fs::path dir = fs::temp_directory_path() / ("psc-cache-file-test-" + std::to_string(getpid()));
    fs::create_directories(dir);
    const fs::path path = dir / "entry.cubin";
    const std::string data(1 << 16, 'c');
    std::vector<int> failures(8, 0);
    std::vector<std::thread> writers;
    for (size_t w = 0; w < failures.size(); ++w) {
        writers.emplace_back([&, w] {
            for (int k = 0; k < 50; ++k) failures[w] += psc::writeCacheFile(path, data) ? 0 : 1;
        });
    }
    for (auto& t : writers) t.join();
    for (int f : failures) CHECK(f == 0);
    std::ifstream in(path, std::ios::binary);
    std::stringstream read;
    read << in.rdbuf();
    CHECK(read.str() == data);
    CHECK(std::distance(fs::directory_iterator(dir), fs::directory_iterator()) == 1);  // no temporary file left
    fs::remove_all(dir);
}

TEST_CASE("cache files: a folder that cannot be written is a failure, not a crash", "[runtime]") {
    CHECK_FALSE(psc::writeCacheFile("/nonexistent-psc-folder/entry", "data"));
}
