#pragma once
// An RGB image for the render command, a PNG writer (libpng), a colour ramp for heat maps, and a
// tiny bitmap font for the heat map's scale labels.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace bvhkit::tools {

struct Rgb {
    std::uint8_t r = 0, g = 0, b = 0;
};

static_assert(sizeof(Rgb) == 3, "pixels are written to PNG rows as packed RGB");

struct Image {
    std::uint32_t width = 0, height = 0;
    std::vector<Rgb> pixels;  // row-major, top row first
    Image(std::uint32_t w, std::uint32_t h) : width(w), height(h), pixels(std::size_t(w) * h) {}
    Rgb& at(std::uint32_t x, std::uint32_t y) { return pixels[std::size_t(y) * width + x]; }
    /// Draws text (digits, '.', ' ', letters used by the labels) with its top-left corner at (x,
    /// y).
    void text(std::uint32_t x, std::uint32_t y, const std::string& s, Rgb colour, int scale = 2);
    void fill(std::uint32_t x0, std::uint32_t y0, std::uint32_t x1, std::uint32_t y1, Rgb colour);
};

/// Throws bvhkit::Error naming the file on failure, or when bvhkit was built without libpng.
void write_png(const std::filesystem::path& path, const Image& image);

/// A perceptually ordered ramp (dark blue, purple, red, orange, pale yellow) for t in [0, 1].
Rgb heat_colour(double t);

}  // namespace bvhkit::tools
