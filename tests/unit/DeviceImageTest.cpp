#include <catch2/catch.hpp>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "plugin_host/DeviceImage.h"
#include "plugin_host/PluginFile.h"

namespace fs = std::filesystem;
using psc_host::DeviceImage;

namespace {

DeviceImage sampleImage() {
    DeviceImage image;
    image.cubin = std::string("\x7f" "ELF", 4) + std::string(1000, '\0') + "cubin";
    image.ptx = {".version 8.0 // unit 0", ".version 8.0 // unit 1, longer"};
    image.stackBytes = 2336;
    return image;
}

void writeFile(const fs::path& p, const std::string& bytes) {
    std::ofstream(p, std::ios::binary) << bytes;
}

}  // namespace

TEST_CASE("device image: decoding gives back what was encoded", "[runtime]") {
    const DeviceImage image = sampleImage();
    DeviceImage back;
    std::string error;
    REQUIRE(psc_host::decodeDeviceImage(psc_host::encodeDeviceImage(image), &back, &error));
    CHECK(error.empty());
    CHECK(back.cubin == image.cubin);
    CHECK(back.ptx == image.ptx);
    CHECK(back.stackBytes == 2336);
}

TEST_CASE("device image: damaged bytes are refused with a reason, at every length", "[runtime]") {
    const std::string bytes = psc_host::encodeDeviceImage(sampleImage());
    for (size_t n = 0; n < bytes.size(); ++n) {
        DeviceImage back;
        std::string error;
        CHECK_FALSE(psc_host::decodeDeviceImage(std::string_view(bytes).substr(0, n), &back, &error));
        CHECK(error.find("damaged") != std::string::npos);
    }
    DeviceImage back;
    std::string error;
    CHECK_FALSE(psc_host::decodeDeviceImage(bytes + "x", &back, &error));
    std::string otherMark = bytes;
    otherMark[6] = '2';
    CHECK_FALSE(psc_host::decodeDeviceImage(otherMark, &back, &error));
    CHECK(error.find("mark") != std::string::npos);
}

TEST_CASE("plugin file: this code's own file, and a section objcopy added to a copy of it", "[runtime]") {
    const std::string self = psc_host::pluginFilePath();
    REQUIRE(!self.empty());
    CHECK(self[0] == '/');
    CHECK(fs::equivalent(self, fs::read_symlink("/proc/self/exe")));

    const fs::path dir = fs::temp_directory_path() / ("psc-plugin-file-test-" + std::to_string(getpid()));
    fs::create_directories(dir);
    const std::string bytes = psc_host::encodeDeviceImage(sampleImage());
    writeFile(dir / "image", bytes);
    const fs::path copy = dir / "with-section";
    const std::string command = "objcopy --add-section .psc_device='" + (dir / "image").string() + "' '" + self + "' '" +
                                copy.string() + "'";
    REQUIRE(std::system(command.c_str()) == 0);

    std::string read, error;
    REQUIRE(psc_host::readElfSection(copy.string(), psc_host::kDeviceImageSection, &read, &error));
    CHECK(read == bytes);
    CHECK_FALSE(psc_host::readElfSection(self, psc_host::kDeviceImageSection, &read, &error));
    CHECK(error.find("no such section") != std::string::npos);
    // A name that only begins like another section's is not that section.
    CHECK_FALSE(psc_host::readElfSection(copy.string(), ".psc_dev", &read, &error));

    CHECK_FALSE(psc_host::readElfSection((dir / "missing").string(), ".psc_device", &read, &error));
    CHECK(error.find((dir / "missing").string()) != std::string::npos);
    writeFile(dir / "text", "not an ELF file at all, but long enough to hold a header of sixty-four bytes");
    CHECK_FALSE(psc_host::readElfSection((dir / "text").string(), ".psc_device", &read, &error));
    CHECK(error.find("not a 64-bit ELF file") != std::string::npos);
    // Cut short anywhere, the file is refused, never read past its end.
    std::ifstream in(copy, std::ios::binary);
    const std::string whole((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    for (size_t n : {size_t{0}, size_t{63}, size_t{64}, whole.size() / 2, whole.size() - 1}) {
        writeFile(dir / "cut", whole.substr(0, n));
        CHECK_FALSE(psc_host::readElfSection((dir / "cut").string(), ".psc_device", &read, &error));
    }
    fs::remove_all(dir);
}
