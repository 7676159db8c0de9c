// An RGB picture in host memory and what the previews and plots draw on it: pixels, filled
// rectangles, lines, text (stb_easy_font's segment font), and its PNG encoding (stb_image_write).
// Row 0 is the top of the picture; x grows to the right.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace mw {

struct Rgb {
    std::uint8_t r = 0, g = 0, b = 0;
};

class Image {
   public:
    Image(int width, int height, Rgb background);
    int width() const { return width_; }
    int height() const { return height_; }
    bool inside(int x, int y) const { return x >= 0 && y >= 0 && x < width_ && y < height_; }
    Rgb get(int x, int y) const { return pixels_[index(x, y)]; }
    // Both ignore a pixel outside the picture, so callers clip nothing themselves.
    void set(int x, int y, Rgb colour) {
        if (inside(x, y)) pixels_[index(x, y)] = colour;
    }
    void blend(int x, int y, Rgb colour, float alpha);  // alpha in [0, 1] over what is there
    const std::vector<Rgb>& pixels() const { return pixels_; }

   private:
    std::size_t index(int x, int y) const { return std::size_t(y) * std::size_t(width_) + std::size_t(x); }
    int width_, height_;
    std::vector<Rgb> pixels_;
};

void fill_rect(Image& image, int x0, int y0, int x1, int y1, Rgb colour);  // [x0, x1) × [y0, y1)
// A line `thickness` pixels wide between two points given in pixels (fractions allowed).
void draw_line(Image& image, double x0, double y0, double x1, double y1, Rgb colour, int thickness = 1);
// Text with its top-left corner at (x, y), each font pixel `scale` pixels wide; ASCII only.
void draw_text(Image& image, int x, int y, const std::string& text, Rgb colour, int scale = 1);
int text_width(const std::string& text, int scale = 1);   // in pixels
int text_height(int scale = 1);                          // of one line, in pixels

// A colour for t in [0, 1] (clamped) from dark blue through teal and green to yellow: perceptually
// ordered and readable by colour-blind viewers, for values such as speed or pressure.
Rgb colour_map(double t);
// The colour scaled by `shade` in [0, 1] (lighting).
Rgb shaded(Rgb colour, double shade);

// The picture as PNG file bytes (8-bit RGB, deflate-compressed).
std::string encode_png(const Image& image);

}  // namespace mw
