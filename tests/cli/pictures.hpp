// Pictures in the command line's tests: a PNG's pixels, and how many of two pictures differ.
#pragma once
#include <string>
#include <vector>

#include <stb_image.h>

#include "cli_helpers.hpp"

namespace cli_test {

// A PNG's RGB bytes (empty when it does not decode).
using Pixels = std::vector<unsigned char>;
inline Pixels png_pixels(const std::string& path) {
    const std::string bytes = slurp(path);
    int width = 0, height = 0, channels = 0;
    unsigned char* data = stbi_load_from_memory(reinterpret_cast<const unsigned char*>(bytes.data()), int(bytes.size()),
                                                &width, &height, &channels, 3);
    if (!data) return {};
    Pixels out(data, data + std::size_t(width) * std::size_t(height) * 3);
    stbi_image_free(data);
    return out;
}

// How many pixels of two pictures of the same size differ.
inline std::size_t differing_pixels(const Pixels& a, const Pixels& b) {
    std::size_t differing = 0;
    for (std::size_t k = 0; k + 2 < a.size() && k + 2 < b.size(); k += 3)
        differing += a[k] != b[k] || a[k + 1] != b[k + 1] || a[k + 2] != b[k + 2];
    return differing;
}

}  // namespace cli_test
