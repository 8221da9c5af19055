// Front-end speed: parse + name resolution + type checking of each sample, in process
// (the parser's tables warm, as in the viewer's hot reload).
//   build/bench/frontend_bench
#include <benchmark/benchmark.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "frontend/frontend.h"

namespace {

std::string read(const std::filesystem::path& path) {
    std::ifstream in(path);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

void checkSample(benchmark::State& state, const std::filesystem::path& path) {
    std::string text = read(path);
    for (auto _ : state) {
        psys::SourceManager sources;
        psys::DiagnosticEngine diags(sources);
        auto program = psys::checkText(path.string(), text, sources, diags);
        if (!program) state.SkipWithError("the sample has errors");
        benchmark::DoNotOptimize(program);
    }
    state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * text.size()));
}

}  // namespace

int main(int argc, char** argv) {
    for (auto& entry : std::filesystem::directory_iterator(PSYS_SAMPLES_DIR))
        if (entry.path().extension() == ".psys")
            benchmark::RegisterBenchmark(("check/" + entry.path().stem().string()).c_str(),
                                         [path = entry.path()](benchmark::State& s) { checkSample(s, path); })
                ->Unit(benchmark::kMicrosecond);
    benchmark::Initialize(&argc, argv);
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
}
