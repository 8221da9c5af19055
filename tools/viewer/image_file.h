// Writing a frame to an image file: the format its extension names (.png, .jpg or .jpeg,
// .bmp, .tga), and every failure said — an unknown extension, a folder that cannot be
// made, a file that cannot be opened, a write the disk refuses (a full file system is
// found when the file is flushed and closed, which stb's own writers do not check).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace psys::viewer {

// The formats by extension, for messages: "png, jpg, bmp or tga".
extern const char* const kImageFormats;

// Why `path` cannot hold an image, judged by its extension alone: nullopt where it can.
std::optional<std::string> imageFormatProblem(const std::string& path);

// Writes `rgba` (width × height, 4 bytes a pixel, top row first) to `path`, making its
// folder; nullopt, or the reason it could not ("No space left on device").
std::optional<std::string> writeImage(const std::string& path, int width, int height, const std::vector<uint8_t>& rgba);

// Why `folder` cannot take recorded frames (made if missing, and written to): nullopt where it can.
std::optional<std::string> folderProblem(const std::string& folder);

}  // namespace psys::viewer
