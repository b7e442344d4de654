#include "image.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "bvhkit/error.hpp"
#include "bvhkit/io/file_access.hpp"

#if BVHKIT_HAVE_PNG
#include <png.h>
#endif

namespace bvhkit::tools {

namespace {

// 3x5 glyphs, one row per 3 bits (MSB left).
struct Glyph {
    char c;
    std::uint8_t rows[5];
};
constexpr Glyph kFont[] = {
    {'0', {7, 5, 5, 5, 7}}, {'1', {2, 6, 2, 2, 7}}, {'2', {7, 1, 7, 4, 7}}, {'3', {7, 1, 7, 1, 7}},
    {'4', {5, 5, 7, 1, 1}}, {'5', {7, 4, 7, 1, 7}}, {'6', {7, 4, 7, 5, 7}}, {'7', {7, 1, 1, 1, 1}},
    {'8', {7, 5, 7, 5, 7}}, {'9', {7, 5, 7, 1, 7}}, {'.', {0, 0, 0, 0, 2}}, {' ', {0, 0, 0, 0, 0}},
    {'n', {0, 6, 5, 5, 5}}, {'o', {0, 7, 5, 5, 7}}, {'d', {1, 7, 5, 5, 7}}, {'e', {7, 5, 7, 4, 7}},
    {'s', {0, 7, 6, 1, 7}}, {'/', {1, 1, 2, 4, 4}}, {'r', {0, 7, 4, 4, 4}}, {'a', {0, 7, 1, 7, 7}},
    {'y', {5, 5, 7, 1, 7}}, {'+', {0, 2, 7, 2, 0}}, {'t', {2, 7, 2, 2, 3}}, {'p', {0, 7, 5, 7, 4}},
    {'h', {4, 4, 7, 5, 5}}, {'c', {0, 7, 4, 4, 7}}, {'i', {2, 0, 2, 2, 2}}, {'l', {2, 2, 2, 2, 2}},
    {',', {0, 0, 0, 2, 4}},
};

}  // namespace

void Image::fill(std::uint32_t x0, std::uint32_t y0, std::uint32_t x1, std::uint32_t y1,
                 Rgb colour) {
    for (std::uint32_t y = y0; y < std::min(y1, height); ++y)
        for (std::uint32_t x = x0; x < std::min(x1, width); ++x) at(x, y) = colour;
}

void Image::text(std::uint32_t x, std::uint32_t y, const std::string& s, Rgb colour, int scale) {
    for (char c : s) {
        for (const Glyph& g : kFont) {
            if (g.c != c) continue;
            for (int row = 0; row < 5; ++row)
                for (int col = 0; col < 3; ++col)
                    if (g.rows[row] >> (2 - col) & 1)
                        fill(x + col * scale, y + row * scale, x + (col + 1) * scale,
                             y + (row + 1) * scale, colour);
        }
        x += 4 * scale;
    }
}

Rgb heat_colour(double t) {
    // Piecewise-linear through hand-picked stops (dark to bright, hue turning blue -> red ->
    // yellow).
    static const double stops[][3] = {{0.05, 0.03, 0.20}, {0.35, 0.07, 0.50}, {0.72, 0.15, 0.40},
                                      {0.95, 0.45, 0.10}, {0.99, 0.85, 0.35}, {1.00, 1.00, 0.85}};
    constexpr int n = 6;
    t = std::clamp(std::isfinite(t) ? t : 0.0, 0.0, 1.0) * (n - 1);
    const int i = std::min(int(t), n - 2);
    const double f = t - i;
    Rgb c;
    std::uint8_t* out[3] = {&c.r, &c.g, &c.b};
    for (int k = 0; k < 3; ++k)
        *out[k] = std::uint8_t(std::lround(255.0 * (stops[i][k] * (1 - f) + stops[i + 1][k] * f)));
    return c;
}

namespace {
#if BVHKIT_HAVE_PNG
void append_png_bytes(png_structp png, png_bytep data, png_size_t size) {
    auto* out = static_cast<std::vector<unsigned char>*>(png_get_io_ptr(png));
    out->insert(out->end(), data, data + size);
}
void flush_nothing(png_structp) {}
#endif
}  // namespace

void write_png(const std::filesystem::path& path, const Image& image) {
#if BVHKIT_HAVE_PNG
    // Encoded in memory and written whole (file_access.hpp), so a failed write leaves no partial
    // picture and is reported.
    std::vector<unsigned char> bytes;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    png_infop info = png ? png_create_info_struct(png) : nullptr;
    if (!png || !info || setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        throw Error(path.string() + ": encoding the PNG failed");
    }
    png_set_write_fn(png, &bytes, append_png_bytes, flush_nothing);
    png_set_IHDR(png, info, image.width, image.height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    for (std::uint32_t y = 0; y < image.height; ++y)
        png_write_row(
            png, reinterpret_cast<png_const_bytep>(&image.pixels[std::size_t(y) * image.width]));
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
    file_detail::write_file(path, bytes, "output file");
#else
    (void)image;
    throw Error(path.string() + ": bvhkit was built without libpng (apt-get install libpng-dev)");
#endif
}

}  // namespace bvhkit::tools
