#include "render/image.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include <stb_easy_font.h>
#include <stb_image_write.h>

namespace mw {

Image::Image(int width, int height, Rgb background) : width_(width), height_(height) {
    if (width <= 0 || height <= 0 || width > 16384 || height > 16384)
        throw std::invalid_argument("an image of " + std::to_string(width) + " x " + std::to_string(height) +
                                    " pixels (each side must be 1 to 16384)");
    pixels_.assign(std::size_t(width) * std::size_t(height), background);
}

void Image::blend(int x, int y, Rgb c, float alpha) {
    if (!inside(x, y)) return;
    alpha = std::clamp(alpha, 0.0f, 1.0f);
    Rgb& p = pixels_[index(x, y)];
    const auto mix = [alpha](std::uint8_t under, std::uint8_t over) {
        return std::uint8_t(std::lround(under + alpha * (float(over) - float(under))));
    };
    p = {mix(p.r, c.r), mix(p.g, c.g), mix(p.b, c.b)};
}

void fill_rect(Image& image, int x0, int y0, int x1, int y1, Rgb colour) {
    x0 = std::max(x0, 0), y0 = std::max(y0, 0);
    x1 = std::min(x1, image.width()), y1 = std::min(y1, image.height());
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) image.set(x, y, colour);
}

void draw_line(Image& image, double x0, double y0, double x1, double y1, Rgb colour, int thickness) {
    if (!std::isfinite(x0) || !std::isfinite(y0) || !std::isfinite(x1) || !std::isfinite(y1)) return;
    // Clip loosely to a frame around the picture, so a point far outside costs no long walk.
    const double margin = 4.0 * thickness + 4.0, w = image.width() + margin, h = image.height() + margin;
    const double steps_needed = std::max(std::fabs(x1 - x0), std::fabs(y1 - y0));
    const int steps = int(std::min(std::ceil(steps_needed), 4.0 * (w + h))) + 1;
    const int lo = -(thickness - 1) / 2, hi = thickness / 2;
    for (int s = 0; s <= steps; ++s) {
        const double t = steps > 0 ? double(s) / steps : 0.0;
        const double x = x0 + t * (x1 - x0), y = y0 + t * (y1 - y0);
        if (x < -margin || y < -margin || x > w || y > h) continue;
        const int px = int(std::lround(x)), py = int(std::lround(y));
        for (int dy = lo; dy <= hi; ++dy)
            for (int dx = lo; dx <= hi; ++dx) image.set(px + dx, py + dy, colour);
    }
}

namespace {
// stb_easy_font writes quads of 4 vertices, each x, y, z (floats) and an RGBA colour: 16 bytes.
struct FontVertex {
    float x, y, z;
    unsigned char colour[4];
};

// The font has glyphs for printable ASCII only and indexes its tables by the character; every
// other byte (a newline, UTF-8) is drawn and measured as '?'.
std::string font_ascii(const std::string& text) {
    std::string ascii = text;
    for (char& c : ascii)
        if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) c = '?';
    return ascii;
}
}  // namespace

void draw_text(Image& image, int x, int y, const std::string& text, Rgb colour, int scale) {
    if (text.empty()) return;
    std::vector<FontVertex> quads(std::max<std::size_t>(text.size() * 64, 256));
    std::string ascii = font_ascii(text);
    const int count = stb_easy_font_print(0, 0, ascii.data(), nullptr, quads.data(), int(quads.size() * sizeof(FontVertex)));
    for (int q = 0; q < count; ++q) {
        const FontVertex* v = &quads[std::size_t(q) * 4];
        const int qx0 = int(std::lround(v[0].x)), qy0 = int(std::lround(v[0].y));
        const int qx1 = int(std::lround(v[2].x)), qy1 = int(std::lround(v[2].y));
        fill_rect(image, x + qx0 * scale, y + qy0 * scale, x + qx1 * scale, y + qy1 * scale, colour);
    }
}

int text_width(const std::string& text, int scale) {
    std::string ascii = font_ascii(text);
    return stb_easy_font_width(ascii.data()) * scale;
}

int text_height(int scale) { return 12 * scale; }

Rgb colour_map(double t) {
    if (!std::isfinite(t)) t = 0;
    t = std::clamp(t, 0.0, 1.0);
    // Anchors chosen by eye for a monotone rise in lightness: navy, blue, teal, green, yellow.
    static const std::array<std::array<double, 3>, 5> anchors{{{0.16, 0.05, 0.33},
                                                               {0.20, 0.30, 0.56},
                                                               {0.13, 0.55, 0.55},
                                                               {0.35, 0.76, 0.36},
                                                               {0.98, 0.90, 0.15}}};
    const double u = t * double(anchors.size() - 1);
    const std::size_t k = std::min<std::size_t>(std::size_t(u), anchors.size() - 2);
    const double f = u - double(k);
    Rgb c;
    std::uint8_t* out[3] = {&c.r, &c.g, &c.b};
    for (int i = 0; i < 3; ++i)
        *out[i] = std::uint8_t(std::lround(255.0 * (anchors[k][i] + f * (anchors[k + 1][i] - anchors[k][i]))));
    return c;
}

Rgb shaded(Rgb c, double shade) {
    shade = std::clamp(std::isfinite(shade) ? shade : 0.0, 0.0, 1.0);
    return {std::uint8_t(std::lround(c.r * shade)), std::uint8_t(std::lround(c.g * shade)),
            std::uint8_t(std::lround(c.b * shade))};
}

std::string encode_png(const Image& image) {
    static_assert(sizeof(Rgb) == 3, "Rgb must be three packed bytes for the PNG rows");
    std::string png;
    const auto append = [](void* context, void* data, int size) {
        static_cast<std::string*>(context)->append(static_cast<const char*>(data), std::size_t(size));
    };
    if (!stbi_write_png_to_func(append, &png, image.width(), image.height(), 3, image.pixels().data(),
                                image.width() * 3))
        throw std::runtime_error("PNG encoding failed");
    return png;
}

}  // namespace mw
