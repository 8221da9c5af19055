// Imports: relative paths, each file once, cycles reported.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>

#include "frontend/frontend.h"
#include "frontend/loader.h"
#include "test_support.h"

using namespace psys;
namespace fs = std::filesystem;

namespace {

// A scratch directory with files, removed afterwards.
struct TempTree {
    fs::path root;
    TempTree() {
        root = fs::temp_directory_path() / ("psys_loader_" + std::to_string(::getpid()) + "_" +
                                            std::to_string(reinterpret_cast<uintptr_t>(this)));
        fs::create_directories(root);
    }
    ~TempTree() { fs::remove_all(root); }
    void write(const std::string& name, const std::string& text) {
        fs::create_directories((root / name).parent_path());
        std::ofstream(root / name) << text;
    }
};

}  // namespace

TEST_CASE("imports resolve relative to the importing file and each file loads once") {
    TempTree t;
    t.write("lib/physics/gravity.psys", "const g = vec3(0, -9.82, 0);\n");
    t.write("lib/forces.psys", "import \"physics/gravity.psys\";\nfn fall(m: float) -> vec3 = g * m;\n");
    t.write("lib/colours.psys", "import \"physics/gravity.psys\";\nconst ember = vec4(1, 0.4, 0, 1);\n");
    t.write("main.psys",
            "import \"lib/forces.psys\";\nimport \"lib/colours.psys\";\n"
            "object a { point(integrate(integrate(fall(0.5))), ember, 1); }\nspawn a;\n");
    SourceManager sources;
    DiagnosticEngine diags(sources);
    auto program = checkFile((t.root / "main.psys").string(), sources, diags);
    REQUIRE_MESSAGE(program, diags.render());
    CHECK(program->modules.size() == 4);  // gravity.psys once, though imported twice
    CHECK(fs::path(program->modules.front()->path).filename() == "gravity.psys");
    CHECK(fs::path(program->main().path).filename() == "main.psys");
}

TEST_CASE("an import cycle names the chain of files") {
    TempTree t;
    t.write("a.psys", "import \"b.psys\";\n");
    t.write("b.psys", "import \"sub/c.psys\";\n");
    t.write("sub/c.psys", "import \"../a.psys\";\n");
    SourceManager sources;
    DiagnosticEngine diags(sources);
    auto program = checkFile((t.root / "a.psys").string(), sources, diags);
    CHECK(program == nullptr);
    std::string out = diags.render();
    CHECK(out.find("import cycle: ") != std::string::npos);
    CHECK(out.find("a.psys → ") != std::string::npos);
    CHECK(out.find("b.psys → ") != std::string::npos);
    CHECK(out.find("c.psys → ") != std::string::npos);
    CHECK(diags.errorCount() == 1);
}

TEST_CASE("a file importing itself is a cycle") {
    TempTree t;
    t.write("self.psys", "import \"./self.psys\";\n");
    SourceManager sources;
    DiagnosticEngine diags(sources);
    CHECK(checkFile((t.root / "self.psys").string(), sources, diags) == nullptr);
    CHECK(diags.render().find("import cycle") != std::string::npos);
}

TEST_CASE("syntax errors in an imported file are reported in that file") {
    TempTree t;
    t.write("lib.psys", "const x = ;\n");
    t.write("main.psys", "import \"lib.psys\";\n");
    SourceManager sources;
    DiagnosticEngine diags(sources);
    CHECK(checkFile((t.root / "main.psys").string(), sources, diags) == nullptr);
    CHECK(diags.render().find("lib.psys:1:11: error: expected an expression") != std::string::npos);
}

TEST_CASE("a directory or a missing main file is an error without a location") {
    TempTree t;
    SourceManager sources;
    DiagnosticEngine diags(sources);
    CHECK(checkFile(t.root.string(), sources, diags) == nullptr);
    CHECK(diags.render().find("it is a directory") != std::string::npos);
}

TEST_CASE("only regular files are read, and none past 1 MiB") {
    TempTree t;
    t.write("main.psys", "import \"/dev/zero\";\n");
    SourceManager sources;
    DiagnosticEngine diags(sources);
    CHECK(checkFile((t.root / "main.psys").string(), sources, diags) == nullptr);
    CHECK(diags.render().find("cannot open imported file `/dev/zero`: it is not a regular file") != std::string::npos);

    t.write("big.psys", std::string(kMaxSourceBytes + 1, ' '));
    t.write("uses_big.psys", "import \"big.psys\";\n");
    SourceManager sources2;
    DiagnosticEngine diags2(sources2);
    CHECK(checkFile((t.root / "uses_big.psys").string(), sources2, diags2) == nullptr);
    CHECK(diags2.render().find("it is larger than 1048576 bytes, the most a source file may be") != std::string::npos);

    // Text handed over directly (an editor's buffer) meets the same limit.
    SourceManager sources3;
    DiagnosticEngine diags3(sources3);
    CHECK(checkText("x.psys", std::string(kMaxSourceBytes + 1, ' '), sources3, diags3) == nullptr);
    CHECK(diags3.render().find("this file is 1048577 bytes, more than the 1048576") != std::string::npos);
}

TEST_CASE("`std/…` is the standard library's, found beside the program, wherever the importer is") {
    TempTree t;
    t.write("deep/down/main.psys", "import \"std/shapes.psys\";\n"
                                   "object p(q: vec3) { point(snapshot(q), white, 1); }\n"
                                   "object e { emit p(in_sphere(1)) count 3; }\nspawn e;\n");
    SourceManager sources;
    DiagnosticEngine diags(sources);
    auto program = checkFile((t.root / "deep/down/main.psys").string(), sources, diags);
    REQUIRE_MESSAGE(program, diags.render());
    CHECK(fs::path(program->modules.front()->path).filename() == "shapes.psys");
    auto dirs = libraryDirectories();
    REQUIRE_FALSE(dirs.empty());
    CHECK(fs::exists(dirs.back() / "std/shapes.psys"));  // beside the test binary (build/share/psys)
}

TEST_CASE("PSYS_LIBRARY comes first: its directories' std/ files take the place of the shipped ones") {
    TempTree t;
    t.write("mine/std/shapes.psys", "fn in_sphere(r: float) -> vec3 = vec3(r, 0, 0);\n");
    struct Env {  // set for this test only
        explicit Env(const std::string& value) { ::setenv("PSYS_LIBRARY", value.c_str(), 1); }
        ~Env() { ::unsetenv("PSYS_LIBRARY"); }
    } env((t.root / "nowhere").string() + ":" + (t.root / "mine").string());
    auto dirs = libraryDirectories();
    REQUIRE(dirs.size() >= 2);
    CHECK(dirs[0] == t.root / "nowhere");
    CHECK(dirs[1] == t.root / "mine");
    t.write("main.psys", "import \"std/shapes.psys\";\nconst c = in_sphere(2);\n");
    SourceManager sources;
    DiagnosticEngine diags(sources);
    auto program = checkFile((t.root / "main.psys").string(), sources, diags);
    REQUIRE_MESSAGE(program, diags.render());
    CHECK(fs::path(program->modules.front()->path) == t.root / "mine/std/shapes.psys");
}

TEST_CASE("a `std/` file the library does not have is an error that says where it looked") {
    SourceManager sources;
    DiagnosticEngine diags(sources);
    auto program = checkText("main.psys", "import \"std/nothing.psys\";\n", sources, diags);
    CHECK(program == nullptr);
    std::string out = diags.render();
    CHECK(out.find("there is no `std/nothing.psys` in the standard library (looked in ") != std::string::npos);
    CHECK(out.find("share/psys") != std::string::npos);
    CHECK(out.find("PSYS_LIBRARY names the directories that hold `std/`") != std::string::npos);
}
