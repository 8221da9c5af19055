// The GPU tests' main: doctest's, after `--gl=MODE` (or PSYS_GL=MODE) chooses the GL the
// whole suite runs on.
//   (none)   the machine's (llvmpipe in CI)
//   strict   strict mode: a full barrier and glFinish after every GPU write (gpu/hazards.h);
//            a test that passes only here points at a missing barrier
//   zink     Mesa's zink over lavapipe (Vulkan on the CPU), which runs work asynchronously
//            and compiles through SPIR-V: what llvmpipe lets pass and a GPU may not
//            (docs/gpu.md, "A second GL")
// Both look for what shows in a sample's first frames: they run 120 (PSYS_TEST_FRAMES;
// tests/run_length.h), the long runs being llvmpipe's, and the sweeps other than "every
// sample draws the same" over four samples (test::sweptSamples). ctest runs each case in each mode
// as a test of its own (CMakeLists.txt).
#define DOCTEST_CONFIG_IMPLEMENT
#include <doctest/doctest.h>

#include <unistd.h>

#include <climits>
#include <cstdio>
#include <cstdlib>
#include <string>

int main(int argc, char** argv) {
    const char* gl = std::getenv("PSYS_GL");
    std::string mode = gl ? gl : "";
    int kept = 1;
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        if (a.rfind("--gl=", 0) == 0) mode = a.substr(5);
        else argv[kept++] = argv[i];
    }
    argc = kept;
    if (mode == "strict") {
        setenv("PSYS_GPU_STRICT", "1", 1);
    } else if (mode == "zink") {
        setenv("LIBGL_ALWAYS_SOFTWARE", "1", 1);
        setenv("GALLIUM_DRIVER", "zink", 1);
        // (lavapipe's window-system code wants one; here nothing is shown)
        char here[PATH_MAX];
        if (!std::getenv("XDG_RUNTIME_DIR") && getcwd(here, sizeof here)) setenv("XDG_RUNTIME_DIR", here, 1);
    } else if (!mode.empty()) {
        std::fprintf(stderr, "--gl is strict or zink, not `%s`\n", mode.c_str());
        return 2;
    }
    if (!mode.empty()) {
        setenv("PSYS_GL", mode.c_str(), 1);  // (test::onSecondGl)
        setenv("PSYS_TEST_FRAMES", "120", 0);
    }
    doctest::Context context(argc, argv);
    return context.run();
}
