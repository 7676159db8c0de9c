// The line charts (render/plot.hpp) and `meltwater plot`: round tick values, their labels, a
// figure drawn from awkward values, and the command end to end on a real run, on one-row and
// empty stats.csv files, and on every kind of bad input.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <algorithm>
#include <random>

#include <stb_image.h>

#include "render/plot.hpp"
#include "tests/cli/cli_helpers.hpp"

using namespace mw;
namespace fs = std::filesystem;

namespace {

bool same(Rgb a, Rgb b) { return a.r == b.r && a.g == b.g && a.b == b.b; }

// The step is 1, 2, 2.5 or 5 times a power of ten.
bool round_step(double step) {
    const double decade = std::pow(10.0, std::floor(std::log10(step) + 1e-9));
    for (const double multiple : {1.0, 2.0, 2.5, 5.0, 10.0})
        if (std::fabs(step - multiple * decade) <= 1e-9 * step) return true;
    return false;
}

// Values beyond 1e300 are drawn at 1e300 (render/plot.cpp); the bounds are met up to rounding.
void check_ticks_cover(double lo, double hi, int most) {
    const plot::Ticks t = plot::nice_ticks(lo, hi, most);
    lo = std::clamp(lo, -1e300, 1e300), hi = std::clamp(hi, -1e300, 1e300);
    const double slack = 1e-6 * std::fabs(t.step) + 1e-12 * std::max(std::fabs(lo), std::fabs(hi));
    CAPTURE(lo);
    CAPTURE(hi);
    CAPTURE(most);
    CHECK(t.count >= 2);
    CHECK(t.count <= std::max(most, lo < 0 && hi > 0 ? 3 : 2));  // -s, 0, s at least across 0
    CHECK(std::isfinite(t.first));
    CHECK(std::isfinite(t.last()));
    CHECK(round_step(t.step));
    CHECK(t.first <= std::min(lo, hi) + slack);
    CHECK(t.last() >= std::max(lo, hi) - slack);
    // The first tick is a multiple of the step, so every tick is.
    CHECK(std::fabs(t.first / t.step - std::round(t.first / t.step)) < 1e-6);
}

// A decoded PNG: its size and RGB pixels.
struct Decoded {
    int width = 0, height = 0;
    std::vector<Rgb> pixels;
    Rgb at(int x, int y) const { return pixels[std::size_t(y) * std::size_t(width) + std::size_t(x)]; }
};

Decoded decode_png(const std::string& bytes) {
    Decoded d;
    int channels = 0;
    unsigned char* data = stbi_load_from_memory(reinterpret_cast<const unsigned char*>(bytes.data()), int(bytes.size()),
                                                &d.width, &d.height, &channels, 3);
    REQUIRE(data != nullptr);
    d.pixels.resize(std::size_t(d.width) * std::size_t(d.height));
    std::memcpy(d.pixels.data(), data, d.pixels.size() * 3);
    stbi_image_free(data);
    return d;
}

long count_colour(const Decoded& d, Rgb colour, int x0, int y0, int x1, int y1) {
    long n = 0;
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) n += same(d.at(x, y), colour);
    return n;
}

// A run directory holding `stats` as its stats.csv (and no summary.json).
std::string run_dir_with(const std::string& name, const std::string& stats) {
    const std::string dir = cli_test::out_dir(name);
    fs::create_directories(dir);
    cli_test::write_text(dir + "/stats.csv", stats);
    return dir;
}

const char* const kHeader =
    "step,time,dt,iterations,density_error_avg,density_error_max,max_speed,kinetic_energy,lost_particles,dt_retries,"
    "diverged,unconverged,ms_neighbors,ms_pcisph,ms_total\n";

}  // namespace

TEST_CASE("plot: nice ticks are round, few enough, and cover the range") {
    const plot::Ticks t = plot::nice_ticks(0.0015, 0.09, 6);
    CHECK(t.first == 0);
    CHECK(t.step == doctest::Approx(0.02));
    CHECK(t.last() == doctest::Approx(0.1));
    const plot::Ticks unit = plot::nice_ticks(0, 1, 6);
    CHECK(unit.step == doctest::Approx(0.2));
    CHECK(unit.count == 6);
    CHECK(plot::nice_ticks(-3, 7, 6).step == doctest::Approx(2.5));  // steps of 2 need 7 ticks, -4 .. 8
    // One value: a range around it; nothing finite: [0, 1]; reversed: the same as in order.
    const plot::Ticks single = plot::nice_ticks(5, 5, 5);
    CHECK(single.first < 5);
    CHECK(single.last() > 5);
    CHECK(plot::nice_ticks(0, 0, 5).last() > 0);
    const plot::Ticks nan = plot::nice_ticks(NAN, INFINITY, 5);
    CHECK(nan.first == 0);
    CHECK(nan.last() == doctest::Approx(1));
    CHECK(plot::nice_ticks(7, -3, 6).step == doctest::Approx(2.5));
    for (const auto& [lo, hi] : std::vector<std::pair<double, double>>{
             {0.0015, 0.09}, {-1e308, 1e308}, {1e-300, 2e-300}, {123456789, 123456790}, {-0.004, -0.001}, {0, 1e-12}})
        for (int most = 1; most <= 10; ++most) check_ticks_cover(lo, hi, most);
    std::mt19937 random(7);
    std::uniform_real_distribution<double> exponent(-12, 12), sign(-1, 1);
    for (int k = 0; k < 2000; ++k) {
        const double a = std::pow(10.0, exponent(random)) * sign(random), b = a + std::pow(10.0, exponent(random));
        check_ticks_cover(a, b, 2 + k % 9);
    }
}

TEST_CASE("plot: tick labels have the digits their step needs") {
    CHECK(plot::tick_label(0.25, 0.25) == "0.25");
    CHECK(plot::tick_label(0.1, 0.02) == "0.10");
    CHECK(plot::tick_label(40, 20) == "40");
    CHECK(plot::tick_label(-3, 1) == "-3");
    CHECK(plot::tick_label(7.5, 2.5) == "7.5");
    CHECK(plot::tick_label(1e-17, 0.1) == "0");  // rounding's residue of 0.1 + 0.2 - 0.3
    CHECK(plot::tick_label(-1e-17, 0.1) == "0");
    CHECK(plot::tick_label(1.5e-5, 5e-6) == "1.5e-5");
    CHECK(plot::tick_label(2e7, 5e6) == "2.0e7");
    CHECK(plot::tick_label(1e-6, 1e-6) == "1e-6");
    CHECK(plot::tick_label(9.99996e6, 1e6) == "1.0e7");  // not "10e6"
    CHECK(plot::tick_label(NAN, 1) == "?");
}

TEST_CASE("plot: a figure of awkward values draws every finite point and survives PNG") {
    plot::Figure figure;
    figure.title = "awkward";
    figure.x_label = "x";
    plot::Panel gaps;
    gaps.title = "gaps";
    gaps.series.push_back({"with gaps", {0, 1, 2, 3, 4, 5}, {1, NAN, 3, INFINITY, 2, 1e308}, plot::palette(0)});
    plot::Panel blow_up;
    blow_up.title = "blows up";
    std::vector<double> xs, ys;
    for (int i = 0; i < 100; ++i) xs.push_back(i * 0.05), ys.push_back(i < 95 ? 1 + 0.01 * i : std::pow(10.0, i - 80));
    blow_up.series.push_back({"", xs, ys, plot::palette(1)});
    plot::Panel empty;
    empty.title = "nothing";
    empty.series.push_back({"none", {0, 1}, {NAN, NAN}, plot::palette(2)});
    figure.panels = {gaps, blow_up, empty};
    figure.marks.push_back({"events", {1.0, 2.5}, {240, 160, 40}});
    const Image image = plot::draw_figure(figure, 900, 400);
    CHECK(image.width() == 900);
    CHECK(image.height() == 400);
    long blue = 0, vermillion = 0, green = 0;
    for (const Rgb& p : image.pixels()) {
        blue += same(p, plot::palette(0));
        vermillion += same(p, plot::palette(1));
        green += same(p, plot::palette(2));
    }
    CHECK(blue > 20);
    CHECK(vermillion > 100);
    CHECK(green == 0);  // the empty panel's series has no point to draw (its legend is left out too)
    const Decoded back = decode_png(encode_png(image));
    CHECK(back.width == 900);
    CHECK(back.height == 400);
    CHECK(same(back.at(450, 200), image.get(450, 200)));
    // The picture's smallest sizes still draw (text scale 1, narrow panels).
    CHECK(plot::draw_figure(figure, 400, 300).width() == 400);
    CHECK(plot::draw_figure(plot::Figure{}, 400, 300).height() == 300);
}

TEST_CASE("plot command: a real short run's picture has the requested size and a curve in every panel") {
    using namespace cli_test;
    const std::string dir = out_dir("plotted_run");
    const Result ran = run("run " + scene_file("tiny.json", tiny_scene_text()) + " --steps 15 --quiet --out " + dir);
    CAPTURE(ran.err);
    REQUIRE(ran.code == 0);
    const Result r = run("plot " + dir + " --width 900 --height 660");
    CAPTURE(r.err);
    REQUIRE(r.code == 0);
    CHECK(contains(r.out, dir + "/plot.png"));
    const Decoded d = decode_png(slurp(dir + "/plot.png"));
    CHECK(d.width == 900);
    CHECK(d.height == 660);
    // Six panels, two columns of three (the figure's choice for this shape). Each has a series in
    // the palette's first colour: dt, iterations, average density error, fluid speed and energy,
    // and the slowest stage. The stage panel's lines are timings that cross and overdraw each other
    // from run to run, so there the curve is any of its first four colours.
    const int top = 50, cell_w = d.width / 2, cell_h = (d.height - top - 20) / 3;
    for (int row = 0; row < 3; ++row)
        for (int column = 0; column < 2; ++column) {
            CAPTURE(row);
            CAPTURE(column);
            const int x0 = column * cell_w, y0 = top + row * cell_h;
            long drawn = count_colour(d, plot::palette(0), x0, y0, x0 + cell_w, y0 + cell_h);
            if (row == 2 && column == 1)
                for (int k = 1; k < 4; ++k) drawn += count_colour(d, plot::palette(k), x0, y0, x0 + cell_w, y0 + cell_h);
            CHECK(drawn > 30);
        }
    // Written atomically: no temporary left beside it.
    for (const auto& entry : fs::directory_iterator(dir)) CHECK(entry.path().filename().string().find(".tmp.") == std::string::npos);
    const Result elsewhere = run("plot " + dir + " --out " + scratch_dir() + "/elsewhere.png");
    CHECK(elsewhere.code == 0);
    CHECK(decode_png(slurp(scratch_dir() + "/elsewhere.png")).width == 1500);
}

TEST_CASE("plot command: a run with pressure sensors gets a panel of their readings") {
    using namespace cli_test;
    const std::string dir = out_dir("plotted_sensors");
    const std::string scene = scene_file(
        "tiny_sensors.json",
        tiny_scene_text(R"("pressure_sensors": [{"name": "floor", "center": [0.05, 0, 0.05], "size": 0.04}])"));
    const Result ran = run("run " + scene + " --steps 15 --quiet --out " + dir);
    CAPTURE(ran.err);
    REQUIRE(ran.code == 0);
    const Result r = run("plot " + dir + " --width 900 --height 880");
    CAPTURE(r.err);
    REQUIRE(r.code == 0);
    const Decoded d = decode_png(slurp(dir + "/plot.png"));
    // Seven panels, two columns of four: the sensors' is the seventh, alone on the last row.
    const int top = 50, cell_w = d.width / 2, cell_h = (d.height - top - 20) / 4;
    CHECK(count_colour(d, plot::palette(0), 0, top + 3 * cell_h, cell_w, top + 4 * cell_h) > 30);
    CHECK(count_colour(d, plot::palette(0), cell_w, top + 3 * cell_h, d.width, top + 4 * cell_h) == 0);
}

TEST_CASE("plot command: one row, no rows, gaps and blow-ups still draw") {
    using namespace cli_test;
    const std::string one = run_dir_with("one_row", std::string(kHeader) + "1,0.001,0.001,3,1e-4,2e-3,0.1,0.5,0,0,0,0,1.5,2.5,4.2\n");
    Result r = run("plot " + one + " --width 640 --height 480");
    CAPTURE(r.err);
    CHECK(r.code == 0);
    const Decoded d = decode_png(slurp(one + "/plot.png"));
    CHECK(d.width == 640);
    CHECK(d.height == 480);
    CHECK(count_colour(d, plot::palette(0), 0, 0, d.width, d.height) > 50);  // the lone points
    const std::string none = run_dir_with("no_rows", kHeader);
    r = run("plot " + none);
    CHECK(r.code == 0);
    CHECK(contains(r.out, "0 steps"));
    const std::string awkward = run_dir_with(
        "awkward", std::string(kHeader) + "1,0.001,0.001,3,1e-4,2e-3,0.1,0.5,0,0,0,0,1.5,2.5,4.2\n" +
                       "2,0.002,0.0005,9,nan,inf,-nan,1e300,0,1,1,1,1.5,2.5,4.2\n" +
                       "3,0.0025,0.0005,4,2e-4,3e-3,1e30,-inf,2,0,0,0,1.5,2.5,4.2\r\n");
    r = run("plot " + awkward + " --out " + awkward + "/awkward.png");
    CAPTURE(r.err);
    CHECK(r.code == 0);
    CHECK(decode_png(slurp(awkward + "/awkward.png")).width == 1500);
    // A column absent (no stage times, no density error): those panels say so, the rest draw.
    const std::string sparse = run_dir_with("sparse", "step,time,dt\n1,0.1,0.1\n2,0.2,0.1\n");
    r = run("plot " + sparse);
    CHECK(r.code == 0);
}

TEST_CASE("plot command: bad input is one line and exit 2") {
    using namespace cli_test;
    const std::string good = run_dir_with("good", std::string(kHeader) + "1,0.001,0.001,3,1e-4,2e-3,0.1,0.5,0,0,0,0,1.5,2.5,4.2\n");
    check_rejected(run("plot"), {"RUN_DIR"});
    check_rejected(run("plot " + scratch_dir() + "/no_such_run"), {"no_such_run", "no such directory"});
    check_rejected(run("plot " + good + "/stats.csv"), {"stats.csv", "not a directory"});
    const std::string empty_dir = out_dir("empty_dir");
    fs::create_directories(empty_dir);
    check_rejected(run("plot " + empty_dir), {"empty_dir", "no stats.csv"});
    check_rejected(run("plot " + run_dir_with("blank", "")), {"stats.csv", "empty"});
    check_rejected(run("plot " + run_dir_with("not_stats", "a,b\n1,2\n")), {"stats.csv", "'step'"});
    check_rejected(run("plot " + run_dir_with("word", "step,time,dt\n1,0.1,0.1\n2,0.2,fast\n")),
                   {"stats.csv line 3", "dt", "'fast'"});
    check_rejected(run("plot " + run_dir_with("short_row", "step,time,dt\n1,0.1,0.1\n2,0.2\n")),
                   {"stats.csv line 3", "2 values", "3"});
    check_rejected(run("plot " + run_dir_with("empty_cell", "step,time,dt\n1,,0.1\n")), {"line 2", "time", "''"});
    check_rejected(run("plot " + good + " --width wide"), {"--width", "'wide'"});
    check_rejected(run("plot " + good + " --width 10"), {"--width", "640"});
    check_rejected(run("plot " + good + " --height 100000"), {"--height", "8000"});
    check_rejected(run("plot " + good + " --out " + good + "/stats.csv/plot.png"), {"cannot write", "plot.png"});
    check_rejected(run("plot " + good + " --out " + good), {"--out", "is a directory"});
    check_rejected(run("plot " + good + " --frobnicate"), {"frobnicate"});
    CHECK(!fs::exists(good + "/plot.png"));
    // A summary.json that is not JSON costs the title its status, not the plot.
    write_text(good + "/summary.json", "{ broken");
    const Result r = run("plot " + good);
    CHECK(r.code == 0);
    CHECK(contains(r.err, "warning"));
    CHECK(fs::exists(good + "/plot.png"));
}
