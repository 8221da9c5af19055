#include "recorder.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <sstream>

#include <fmt/format.h>

#include "image_file.h"

namespace psys::viewer {
namespace {

std::string extension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext;
}

// `text` in single quotes for sh.
std::string quoted(const std::string& text) {
    std::string out = "'";
    for (char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

}  // namespace

bool Recorder::isVideo(const std::string& path) {
    std::string ext = extension(path);
    return ext == ".mp4" || ext == ".gif";
}

bool Recorder::haveFfmpeg() {
    const char* paths = std::getenv("PATH");
    std::istringstream in(paths ? paths : "");
    for (std::string dir; std::getline(in, dir, ':');)
        if (!dir.empty() && ::access((dir + "/ffmpeg").c_str(), X_OK) == 0) return true;
    return false;
}

std::optional<std::string> Recorder::problem(const std::string& path) {
    if (!isVideo(path)) return folderProblem(path);
    if (!haveFfmpeg()) return std::string("ffmpeg is not on the PATH (it records .mp4 and .gif; a folder takes PNG frames)");
    std::filesystem::path folder = std::filesystem::path(path).parent_path();
    if (!folder.empty())
        if (auto p = folderProblem(folder.string())) return p;
    return std::nullopt;
}

std::unique_ptr<Recorder> Recorder::open(const std::string& path, int width, int height, double fps, std::string& error) {
    if (auto p = problem(path)) {
        error = "cannot write `" + path + "`: " + *p;
        return nullptr;
    }
    std::unique_ptr<Recorder> r(new Recorder());
    r->path_ = path;
    r->width_ = width;
    r->height_ = height;
    if (!isVideo(path)) return r;
    // A broken pipe (ffmpeg gone) is a write error to report, not a signal that kills us.
    std::signal(SIGPIPE, SIG_IGN);
    // H.264 wants even sizes and 4:2:0 for players to take it; a GIF its own palette.
    std::string filter = extension(path) == ".gif"
                             ? "-vf 'split[a][b];[a]palettegen[p];[b][p]paletteuse' -loop 0"
                             : "-vf 'pad=ceil(iw/2)*2:ceil(ih/2)*2' -c:v libx264 -pix_fmt yuv420p -preset veryfast -crf 18";
    std::string command = fmt::format(
        "ffmpeg -nostdin -hide_banner -loglevel error -y -f rawvideo -pix_fmt rgba -s {}x{} -framerate {:.6g} -i - {} {}",
        width, height, fps, filter, quoted(path));
    r->pipe_ = ::popen(command.c_str(), "w");
    if (!r->pipe_) {
        error = "cannot write `" + path + "`: cannot run ffmpeg: " + std::strerror(errno);
        return nullptr;
    }
    return r;
}

Recorder::~Recorder() {
    if (pipe_) ::pclose(pipe_);
}

std::optional<std::string> Recorder::add(int index, const std::vector<uint8_t>& rgba) {
    if (!pipe_) {
        std::string file = fmt::format("{}/frame_{:06}.png", path_, index);
        if (auto p = writeImage(file, width_, height_, rgba)) return "cannot write `" + file + "`: " + *p;
        ++frames_;
        return std::nullopt;
    }
    if (std::fwrite(rgba.data(), 1, rgba.size(), pipe_) != rgba.size()) {
        int e = errno;
        return "cannot write `" + path_ + "`: ffmpeg took no more frames (" + std::strerror(e) + ")";
    }
    ++frames_;
    return std::nullopt;
}

std::optional<std::string> Recorder::finish() {
    if (!pipe_) return std::nullopt;
    int status = ::pclose(pipe_);
    pipe_ = nullptr;
    if (status == -1) return "cannot write `" + path_ + "`: " + std::strerror(errno);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
        return fmt::format("cannot write `{}`: ffmpeg failed (exit status {})", path_,
                           WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status));
    return std::nullopt;
}

}  // namespace psys::viewer
