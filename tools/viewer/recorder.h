// Recording frames: into a folder as numbered PNGs, or into a video — .mp4 (H.264) or
// .gif — through a pipe to ffmpeg where it is on the PATH. The frames are raw RGBA down
// the pipe, at the rate the recording asks (a frame a fixed step: the clip plays at the
// simulation's speed). Every failure is said with its reason: no ffmpeg, a folder that
// cannot be written, ffmpeg refusing or dying mid-clip (a broken pipe is an error, not a
// signal that ends the viewer).
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace psys::viewer {

class Recorder {
public:
    // `path` ending in .mp4 or .gif: a video at `fps` frames a second; anything else: a
    // folder of frame_NNNNNN.png. Null, and `error` set, where it cannot record there.
    static std::unique_ptr<Recorder> open(const std::string& path, int width, int height, double fps, std::string& error);
    // Why `path` cannot take a recording, known before anything runs: nullopt where it can.
    static std::optional<std::string> problem(const std::string& path);
    static bool isVideo(const std::string& path);
    static bool haveFfmpeg();
    ~Recorder();
    Recorder(const Recorder&) = delete;
    Recorder& operator=(const Recorder&) = delete;

    // Frame `index` (numbers the PNGs), top row first; nullopt, or why it was not written
    // (FILE: reason).
    std::optional<std::string> add(int index, const std::vector<uint8_t>& rgba);
    // Ends the video (ffmpeg writes its file): nullopt, or why it failed.
    std::optional<std::string> finish();

    const std::string& path() const { return path_; }
    int frames() const { return frames_; }

private:
    Recorder() = default;
    std::string path_;
    int width_ = 0, height_ = 0, frames_ = 0;
    FILE* pipe_ = nullptr;  // ffmpeg's standard input, for a video
};

}  // namespace psys::viewer
