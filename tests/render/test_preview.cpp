// The frame preview (render/preview.hpp): where things land in the picture, what hides what, how
// the field is coloured, how the default camera frames a box, and that the result is the same at
// any thread count and survives PNG encoding.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <stdexcept>

#include <omp.h>
#include <stb_image.h>

#include "render/preview.hpp"

using namespace mw;

namespace {

// No shading of anything drawn gives pure magenta, so "not background" means "something drawn".
const Rgb kBackground{255, 0, 255};

bool same(Rgb a, Rgb b) { return a.r == b.r && a.g == b.g && a.b == b.b; }

PreviewStyle plain_style(int supersample = 1) {
    PreviewStyle style;
    style.background_top = style.background_bottom = kBackground;
    style.show_legend = false;
    style.supersample = supersample;
    return style;
}

// Looking down -z from z = 5 at the origin: the picture's centre is (480, 270), and a point (x, y, 0)
// lands focal / 5 pixels per unit away from it.
PreviewCamera front_camera() {
    PreviewCamera camera;
    camera.eye = {0, 0, 5};
    camera.target = {0, 0, 0};
    camera.fov_y_degrees = 35;
    return camera;
}
const double kFocal = 270 / std::tan(17.5 * M_PI / 180);

void add_particle(PreviewFrame& frame, float x, float y, float z, float value, PreviewKind kind = PreviewKind::fluid) {
    frame.positions.insert(frame.positions.end(), {x, y, z});
    frame.values.push_back(value);
    frame.kinds.push_back(kind);
}

struct Coverage {
    long long count = 0;
    double mean_x = 0, mean_y = 0;  // of the drawn pixels' centres
    int x0 = 1 << 30, y0 = 1 << 30, x1 = -1, y1 = -1;
};

Coverage coverage(const Image& image, Rgb background = kBackground) {
    Coverage c;
    for (int y = 0; y < image.height(); ++y)
        for (int x = 0; x < image.width(); ++x)
            if (!same(image.get(x, y), background)) {
                ++c.count;
                c.mean_x += x + 0.5, c.mean_y += y + 0.5;
                c.x0 = std::min(c.x0, x), c.x1 = std::max(c.x1, x), c.y0 = std::min(c.y0, y), c.y1 = std::max(c.y1, y);
            }
    if (c.count) c.mean_x /= double(c.count), c.mean_y /= double(c.count);
    return c;
}

}  // namespace

TEST_CASE("preview: a particle at the camera's target lands in the picture's centre, as a disc of its projected radius") {
    PreviewFrame frame;
    frame.particle_radius = 0.05;
    add_particle(frame, 0, 0, 0, 1);
    for (int supersample : {1, 2}) {
        const Image image = render_preview(frame, front_camera(), plain_style(supersample));
        CHECK(image.width() == 960);
        CHECK(image.height() == 540);
        const Coverage c = coverage(image);
        CHECK(c.mean_x == doctest::Approx(480).epsilon(1e-4));
        CHECK(c.mean_y == doctest::Approx(270).epsilon(1e-4));
        const double radius_px = 0.05 * kFocal / 5;  // about 8.6
        CHECK(c.x1 - c.x0 + 1 == doctest::Approx(2 * radius_px).epsilon(0.15));
        CHECK(c.y1 - c.y0 + 1 == doctest::Approx(2 * radius_px).epsilon(0.15));
        // Lit from the upper left: the upper-left part of the disc is brighter than the lower-right.
        const Rgb upper_left = image.get(476, 266), lower_right = image.get(484, 274);
        CHECK(int(upper_left.r) + upper_left.g + upper_left.b > int(lower_right.r) + lower_right.g + lower_right.b);
    }
}

TEST_CASE("preview: a particle behind the camera, or hidden, draws nothing, and a wall particle only when asked") {
    PreviewFrame frame;
    frame.particle_radius = 0.05;
    add_particle(frame, 0, 0, 6, 1);     // 1 behind the eye, on the line of sight
    add_particle(frame, 0, 0, 5, 1);     // in the eye's own plane
    add_particle(frame, 0, 0, 0, 1, PreviewKind::hidden);
    CHECK(coverage(render_preview(frame, front_camera(), plain_style())).count == 0);

    PreviewFrame wall;
    wall.particle_radius = 0.05;
    add_particle(wall, 0, 0, 0, 1, PreviewKind::boundary);
    PreviewStyle style = plain_style();
    CHECK(coverage(render_preview(wall, front_camera(), style)).count == 0);
    style.show_boundary = true;
    CHECK(coverage(render_preview(wall, front_camera(), style)).count > 100);
}

TEST_CASE("preview: the nearer of two splats on one line of sight hides the farther, whatever their order") {
    // The near one (z = 1) is at the top of the range (yellow), the far one (z = -1) at the bottom (navy).
    PreviewFrame near_first, far_first;
    for (PreviewFrame* f : {&near_first, &far_first}) f->particle_radius = 0.05, f->field_range = std::array<double, 2>{0, 1};
    add_particle(near_first, 0, 0, 1, 1);
    add_particle(near_first, 0, 0, -1, 0);
    add_particle(far_first, 0, 0, -1, 0);
    add_particle(far_first, 0, 0, 1, 1);
    const Image a = render_preview(near_first, front_camera(), plain_style());
    const Image b = render_preview(far_first, front_camera(), plain_style());
    const Rgb centre = a.get(480, 270);
    CHECK(centre.r > 2 * centre.b);  // yellow, not navy
    CHECK(a.pixels().size() == b.pixels().size());
    bool identical = true;
    for (std::size_t i = 0; i < a.pixels().size(); ++i) identical = identical && same(a.pixels()[i], b.pixels()[i]);
    CHECK(identical);
    // Only the near splat's disc shows: the far one is smaller on the screen and lies wholly behind.
    const double near_radius_px = 0.05 * kFocal / 4;
    const Coverage c = coverage(a);
    CHECK(c.x1 - c.x0 + 1 == doctest::Approx(2 * near_radius_px).epsilon(0.15));
}

TEST_CASE("preview: the field's low and high values get the colour bar's two ends, each at its own particle") {
    PreviewFrame frame;
    frame.particle_radius = 0.05;
    add_particle(frame, -1, 0, 0, 0);    // left: the lowest value
    add_particle(frame, 1, 0, 0, 10);    // right: the highest
    const Image image = render_preview(frame, front_camera(), plain_style());
    const int left = int(480 - kFocal / 5), right = int(480 + kFocal / 5);
    const Rgb low = image.get(left, 270), high = image.get(right, 270);
    CHECK(low.b > low.r);   // navy
    CHECK(low.b > low.g);
    CHECK(high.r > high.b);  // yellow
    CHECK(high.g > high.b);
    // The same through an explicit range that puts both values at its bottom: both navy.
    frame.field_range = std::array<double, 2>{10, 20};
    const Image clamped = render_preview(frame, front_camera(), plain_style());
    CHECK(clamped.get(right, 270).b > clamped.get(right, 270).r);
}

TEST_CASE("preview: the automatic range spans the fluid's 1st to 99th percentile") {
    PreviewFrame frame;
    for (int i = 0; i <= 1000; ++i) add_particle(frame, 0, 0, 0, float(i) / 1000);
    add_particle(frame, 0, 0, 0, 1e6f, PreviewKind::solid);  // not fluid: not counted
    frame.values[500] = 1e9f;                                // one outlier among the fluid
    const std::array<double, 2> range = preview_field_range(frame);
    CHECK(range[0] == doctest::Approx(0.01).epsilon(0.02));
    CHECK(range[1] == doctest::Approx(0.99).epsilon(0.02));

    PreviewFrame still;
    for (int i = 0; i < 10; ++i) add_particle(still, 0, 0, 0, 0);
    const std::array<double, 2> rest = preview_field_range(still);
    CHECK(rest[0] == 0);
    CHECK(rest[1] > 0);
}

TEST_CASE("preview: a mesh triangle covers the pixels inside its projection and hides what is behind it") {
    PreviewFrame frame;
    frame.particle_radius = 0.05;
    PreviewMesh mesh;
    mesh.vertices = {-1, -1, 0, 1, -1, 0, -1, 1, 0};  // the lower-left half of a square facing the camera
    mesh.triangles = {0, 1, 2};
    mesh.colour = {200, 100, 0};
    frame.meshes.push_back(mesh);
    add_particle(frame, -0.6f, -0.6f, -1, 1);  // behind the triangle, on the line of sight of (-0.5, -0.5, 0)
    add_particle(frame, 0.6f, 0.6f, 0, 1);     // beside it, in its plane's upper-right half
    const Image image = render_preview(frame, front_camera(), plain_style());
    const double s = kFocal / 5;  // pixels per unit at the triangle's depth
    const Rgb inside = image.get(int(480 - 0.5 * s), int(270 + 0.5 * s));
    CHECK(inside.r > inside.g);  // the mesh's orange, shaded
    CHECK(inside.g > inside.b);
    CHECK(inside.b == 0);  // not the yellow particle behind (its blue is above 0)
    CHECK(same(image.get(int(480 + 0.3 * s), int(270 - 0.3 * s)), kBackground));  // across the diagonal
    const Rgb particle = image.get(int(480 + 0.6 * s), int(270 - 0.6 * s));
    CHECK(particle.b > 0);  // the particle beside the triangle shows
    // Its area in pixels: half of a 2s x 2s square, plus the particle beside it.
    frame.kinds = {PreviewKind::hidden, PreviewKind::hidden};
    const Coverage c = coverage(render_preview(frame, front_camera(), plain_style()));
    CHECK(double(c.count) == doctest::Approx(2 * s * s).epsilon(0.02));
    CHECK(c.x0 == doctest::Approx(480 - s).epsilon(0.01));
    CHECK(c.y1 == doctest::Approx(270 + s).epsilon(0.01));
}

TEST_CASE("preview: a splat's depth follows the sphere's bulge: a sphere sunk into a plane shows only its cap") {
    PreviewFrame frame;
    frame.particle_radius = 0.05;
    add_particle(frame, 0, 0, -0.04f, 0, PreviewKind::solid);  // its centre 0.8 radii behind the plane z = 0
    PreviewMesh plane;
    plane.vertices = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
    plane.triangles = {0, 1, 2, 0, 2, 3};
    plane.colour = {255, 0, 0};
    frame.meshes.push_back(plane);
    PreviewStyle style = plain_style();
    style.solid_colour = {0, 255, 0};
    const Image image = render_preview(frame, front_camera(), style);
    // The disc is about 8.5 pixels across its radius; the cap pokes through within 0.6 of it.
    CHECK(image.get(480, 270).g > 0);
    CHECK(image.get(482, 270).g > 0);
    CHECK(image.get(486, 270).g == 0);
    CHECK(image.get(486, 270).r > 0);
}

TEST_CASE("preview: a triangle reaching behind the camera is cut at the near plane, not thrown away or flipped") {
    PreviewFrame frame;
    PreviewMesh ground;  // on the plane y = -1, from in front of the eye to 5 behind it
    ground.vertices = {-1, -1, 0, 1, -1, 0, 0, -1, 10};
    ground.triangles = {0, 1, 2};
    frame.meshes.push_back(ground);
    const Coverage c = coverage(render_preview(frame, front_camera(), plain_style()));
    CHECK(c.count > 1000);
    CHECK(c.y0 > 270);       // all below the horizon, as the plane is below the eye
    CHECK(c.y1 == 539);      // down to the picture's bottom edge, where the plane passes under the eye
    const Image image = render_preview(frame, front_camera(), plain_style());
    CHECK_FALSE(same(image.get(480, 539), kBackground));
}

TEST_CASE("preview: a translucent mesh tints what lies behind it and leaves what is in front alone") {
    PreviewFrame frame;
    frame.particle_radius = 0.05;
    PreviewMesh sheet;
    sheet.vertices = {-2, -2, 0, 2, -2, 0, 2, 2, 0, -2, 2, 0};
    sheet.triangles = {0, 1, 2, 0, 2, 3};
    sheet.colour = {0, 0, 255};
    sheet.opacity = 0.5f;
    frame.meshes.push_back(sheet);
    add_particle(frame, 0, 0, 1, 1, PreviewKind::solid);  // in front of the sheet
    PreviewStyle style = plain_style();
    style.solid_colour = {0, 255, 0};
    const Image image = render_preview(frame, front_camera(), style);
    const Rgb front = image.get(478, 268), open = image.get(480 + int(kFocal / 5), 270);
    CHECK(front.b == 0);  // the particle, untinted
    CHECK(front.g > 0);
    CHECK(open.r > 64);  // half the magenta background, half the sheet's blue
    CHECK(open.r < 192);
    CHECK(open.b > open.r);
}

TEST_CASE("preview: the default camera frames every corner of a domain box, from above and in front") {
    const std::array<PreviewVec, 2> boxes[] = {{PreviewVec{0, 0, 0}, PreviewVec{1.6, 1.0, 0.8}},
                                               {PreviewVec{-1, 0, -1}, PreviewVec{1, 4, 1}},      // a tall tower
                                               {PreviewVec{0, 0, 0}, PreviewVec{10, 0.5, 3}},     // a long flat channel
                                               {PreviewVec{5, -2, 7}, PreviewVec{5.2, -1.9, 7.1}}};  // small, far from the origin
    for (const auto& box : boxes) {
        CAPTURE(box[1][0]);
        const PreviewCamera camera = default_camera(box[0], box[1]);
        const PreviewVec mid{0.5 * (box[0][0] + box[1][0]), 0.5 * (box[0][1] + box[1][1]), 0.5 * (box[0][2] + box[1][2])};
        CHECK(camera.eye[1] > mid[1]);  // above
        CHECK(camera.eye[2] > mid[2]);  // in front
        PreviewFrame corners;
        const double size = std::hypot(box[1][0] - box[0][0], box[1][1] - box[0][1], box[1][2] - box[0][2]);
        corners.particle_radius = 1e-4 * size;  // each corner a pixel or two
        for (int k = 0; k < 8; ++k) {
            PreviewFrame one;
            one.particle_radius = corners.particle_radius;
            add_particle(one, float(box[k & 1][0]), float(box[(k >> 1) & 1][1]), float(box[(k >> 2) & 1][2]), 0);
            add_particle(corners, float(box[k & 1][0]), float(box[(k >> 1) & 1][1]), float(box[(k >> 2) & 1][2]), 0);
            CHECK(coverage(render_preview(one, camera, plain_style())).count > 0);
        }
        // All of them inside, off the edges, and the box filling most of the picture one way.
        const Coverage c = coverage(render_preview(corners, camera, plain_style()));
        CHECK(c.x0 >= 10);
        CHECK(c.y0 >= 10);
        CHECK(c.x1 < 950);
        CHECK(c.y1 < 530);
        CHECK((c.x1 - c.x0 > 0.7 * 960 || c.y1 - c.y0 > 0.7 * 540));
        CHECK(0.5 * (c.x0 + c.x1) == doctest::Approx(480).epsilon(0.05));
        CHECK(0.5 * (c.y0 + c.y1) == doctest::Approx(270).epsilon(0.05));
    }
}

TEST_CASE("preview: a whole scene is the same picture at any thread count, and its PNG decodes to it") {
    PreviewFrame frame;
    frame.particle_radius = 0.01;
    frame.domain = std::array<PreviewVec, 2>{PreviewVec{0, 0, 0}, PreviewVec{1.6, 1.0, 0.8}};
    frame.field_name = "speed, m/s";
    frame.caption = "t = 0.250 s  frame 12";
    std::uint32_t seed = 12345;
    const auto random = [&seed] { return float((seed = seed * 1664525u + 1013904223u) >> 8) / float(1 << 24); };
    for (int i = 0; i < 20000; ++i)
        add_particle(frame, 0.6f * random(), 0.5f * random(), 0.8f * random(), random(),
                     i % 10 == 0 ? PreviewKind::solid : PreviewKind::fluid);
    PreviewMesh box;
    box.vertices = {1, 0, 0.3f, 1.3f, 0, 0.3f, 1.3f, 0.3f, 0.3f, 1, 0.3f, 0.3f};
    box.triangles = {0, 1, 2, 0, 2, 3};
    frame.meshes.push_back(box);
    const PreviewCamera camera = default_camera((*frame.domain)[0], (*frame.domain)[1]);

    const int threads = omp_get_max_threads();
    omp_set_num_threads(1);
    const Image one = render_preview(frame, camera);
    omp_set_num_threads(std::max(2, threads));
    const Image many = render_preview(frame, camera);
    omp_set_num_threads(threads);
    bool identical = true;
    for (std::size_t i = 0; i < one.pixels().size(); ++i) identical = identical && same(one.pixels()[i], many.pixels()[i]);
    CHECK(identical);

    // The legend's bar holds both ends of the colour map; the caption's panel is drawn at the top left.
    bool bar_top = false, bar_bottom = false;
    for (int y = 0; y < 300; ++y)
        for (int x = 800; x < 960; ++x) {
            bar_top = bar_top || same(one.get(x, y), colour_map(1.0));
            bar_bottom = bar_bottom || same(one.get(x, y), colour_map(0.0));
        }
    CHECK(bar_top);
    CHECK(bar_bottom);

    const std::string png = encode_png(one);
    REQUIRE(png.size() > 8);
    CHECK(png.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0);
    int w = 0, h = 0, channels = 0;
    unsigned char* decoded = stbi_load_from_memory(reinterpret_cast<const unsigned char*>(png.data()), int(png.size()),
                                                   &w, &h, &channels, 3);
    REQUIRE(decoded != nullptr);
    CHECK(w == 960);
    CHECK(h == 540);
    bool round_trip = true;
    for (std::size_t i = 0; i < one.pixels().size(); ++i)
        round_trip = round_trip && same(one.pixels()[i], {decoded[3 * i], decoded[3 * i + 1], decoded[3 * i + 2]});
    stbi_image_free(decoded);
    CHECK(round_trip);
}

TEST_CASE("preview: inconsistent input is refused with a reason") {
    PreviewFrame frame;
    add_particle(frame, 0, 0, 0, 1);
    frame.values.push_back(2);  // one value too many
    CHECK_THROWS_AS(render_preview(frame, front_camera()), std::invalid_argument);
    frame.values.pop_back();
    PreviewMesh mesh;
    mesh.vertices = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    mesh.triangles = {0, 1, 3};  // no vertex 3
    frame.meshes.push_back(mesh);
    CHECK_THROWS_AS(render_preview(frame, front_camera()), std::invalid_argument);
    frame.meshes.clear();
    PreviewCamera blind = front_camera();
    blind.eye = blind.target;
    CHECK_THROWS_AS(render_preview(frame, blind), std::invalid_argument);
    PreviewStyle huge;
    huge.supersample = 8;
    CHECK_THROWS_AS(render_preview(frame, front_camera(), huge), std::invalid_argument);
}
