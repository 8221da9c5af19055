#include "image_file.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include <stb_image_write.h>

namespace psys::viewer {
namespace {

enum class Format { Png, Jpg, Bmp, Tga };

std::optional<Format> formatOf(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (ext == ".png") return Format::Png;
    if (ext == ".jpg" || ext == ".jpeg") return Format::Jpg;
    if (ext == ".bmp") return Format::Bmp;
    if (ext == ".tga") return Format::Tga;
    return std::nullopt;
}

void append(void* context, void* data, int size) {
    auto* out = static_cast<std::vector<uint8_t>*>(context);
    const auto* bytes = static_cast<const uint8_t*>(data);
    out->insert(out->end(), bytes, bytes + size);
}

}  // namespace

const char* const kImageFormats = "png, jpg, bmp or tga";

std::optional<std::string> imageFormatProblem(const std::string& path) {
    if (formatOf(path)) return std::nullopt;
    std::string ext = std::filesystem::path(path).extension().string();
    return (ext.empty() ? std::string("no extension") : "an unknown image format `" + ext + "`") + " (it writes " +
           kImageFormats + ")";
}

std::optional<std::string> writeImage(const std::string& path, int width, int height, const std::vector<uint8_t>& rgba) {
    auto format = formatOf(path);
    if (!format) return imageFormatProblem(path);
    std::vector<uint8_t> bytes;  // encoded in memory, then written with every error checked
    int ok = 0;
    switch (*format) {
        case Format::Png: ok = stbi_write_png_to_func(append, &bytes, width, height, 4, rgba.data(), width * 4); break;
        case Format::Jpg: ok = stbi_write_jpg_to_func(append, &bytes, width, height, 4, rgba.data(), 95); break;
        case Format::Bmp: ok = stbi_write_bmp_to_func(append, &bytes, width, height, 4, rgba.data()); break;
        case Format::Tga: ok = stbi_write_tga_to_func(append, &bytes, width, height, 4, rgba.data()); break;
    }
    if (!ok) return std::string("the image could not be encoded");
    std::filesystem::path p(path);
    std::error_code made;
    if (p.has_parent_path()) std::filesystem::create_directories(p.parent_path(), made);
    if (made) return made.message();
    FILE* file = std::fopen(path.c_str(), "wb");
    if (!file) return std::string(std::strerror(errno));
    bool written = std::fwrite(bytes.data(), 1, bytes.size(), file) == bytes.size();
    int error = written ? 0 : errno;
    if (std::fflush(file) != 0 && !error) error = errno;
    if (std::fclose(file) != 0 && !error) error = errno;
    if (!written && !error) error = EIO;
    if (error) return std::string(std::strerror(error));
    return std::nullopt;
}

std::optional<std::string> folderProblem(const std::string& folder) {
    std::error_code made;
    std::filesystem::create_directories(folder, made);
    if (made) return made.message();
    if (!std::filesystem::is_directory(folder)) return std::string("not a folder");
    if (::access(folder.c_str(), W_OK) != 0) return std::string(std::strerror(errno));
    return std::nullopt;
}

}  // namespace psys::viewer
