#include "apps/checkpoint_file.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <ostream>

#include "apps/atomic_file.hpp"
#include "apps/cli_common.hpp"
#include "backend/config.hpp"
#include "common/errors.hpp"

namespace mw {

namespace {
constexpr int kFormatVersion = 1;
constexpr const char* kMagic = "MELTWATER CHECKPOINT ";

// FNV-1a, 64-bit: enough to tell a damaged file from a whole one (not a defence against tampering).
struct Fnv1a {
    std::uint64_t hash = 0xcbf29ce484222325ull;
    void add(const unsigned char* data, std::size_t n) {
        for (std::size_t k = 0; k < n; ++k) {
            hash ^= data[k];
            hash *= 0x100000001b3ull;
        }
    }
};

// Little-endian on every host this builds for (x86-64, aarch64); written byte by byte anyway, so
// that the file does not depend on it.
void put_u64(std::ostream& out, std::uint64_t v) {
    unsigned char bytes[8];
    for (int k = 0; k < 8; ++k) bytes[k] = static_cast<unsigned char>(v >> (8 * k));
    out.write(reinterpret_cast<const char*>(bytes), 8);
}
std::uint64_t get_u64(const unsigned char* bytes) {
    std::uint64_t v = 0;
    for (int k = 0; k < 8; ++k) v |= std::uint64_t(bytes[k]) << (8 * k);
    return v;
}
}  // namespace

void write_checkpoint(const std::string& path, const Checkpoint& c) {
    SceneJson header;
    header["format"] = "meltwater checkpoint";
    header["real_bytes"] = sizeof(Real);
    header["backend"] = c.backend;
    header["step"] = c.step;
    header["time"] = c.time;
    header["next_frame_time"] = c.next_frame_time;
    header["frame_times"] = c.frame_times;
    header["scene"] = c.scene;
    SceneJson blocks = SceneJson::array();
    for (const StateBlock& b : c.state.blocks())
        blocks.push_back({{"name", b.name}, {"element_bytes", b.element_bytes}, {"count", b.count}});
    header["blocks"] = blocks;
    const std::string header_text = header.dump(-1, ' ', false, SceneJson::error_handler_t::replace);

    write_file_atomically(path, [&](std::ostream& out) {
        out << kMagic << kFormatVersion << '\n';
        put_u64(out, header_text.size());
        out.write(header_text.data(), static_cast<std::streamsize>(header_text.size()));
        Fnv1a sum;
        sum.add(reinterpret_cast<const unsigned char*>(header_text.data()), header_text.size());
        for (const StateBlock& b : c.state.blocks()) {
            out.write(reinterpret_cast<const char*>(b.bytes.data()), static_cast<std::streamsize>(b.bytes.size()));
            sum.add(b.bytes.data(), b.bytes.size());
        }
        put_u64(out, sum.hash);
    });
}

namespace {
// The header's step and time are what a resumed run reports and numbers its frames from; the
// state's are what it continues. The checksum only says the file is as written, so a file made
// or edited with a valid checksum is still checked for the two agreeing, and for a frame clock
// that runs forward and not past the state's time.
void check_clock(const Checkpoint& c, const std::string& where) {
    const long state_step = c.state.get_value<long>("step");
    const double state_time = c.state.get_value<double>("time");
    if (state_step != c.step || state_time != c.time)
        throw InputError(where + " is inconsistent: its header says step " + std::to_string(c.step) + ", t = " +
                         format_number(c.time) + " s, its state step " + std::to_string(state_step) + ", t = " +
                         format_number(state_time) + " s");
    double previous = 0;
    for (std::size_t k = 0; k < c.frame_times.size(); ++k) {
        const double t = c.frame_times[k];
        if (!(t >= previous && t <= c.time))
            throw InputError(where + " is inconsistent: frame " + std::to_string(k) + " is at t = " + format_number(t) +
                             " s, " + (t > c.time ? "after the state's t = " + format_number(c.time) + " s"
                                                  : "before the frame ahead of it"));
        previous = t;
    }
    if (!(c.next_frame_time >= previous && std::isfinite(c.next_frame_time)))
        throw InputError(where + " is inconsistent: its next frame is due at t = " + format_number(c.next_frame_time) +
                         " s, before its last frame at t = " + format_number(previous) + " s");
}
}  // namespace

Checkpoint read_checkpoint(const std::string& path) {
    const std::string where = "checkpoint '" + path + "'";
    std::error_code error;
    if (!std::filesystem::exists(path, error)) throw InputError(where + " does not exist");
    if (std::filesystem::is_directory(path, error)) throw InputError(where + " is a directory");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError("cannot read " + where);
    const std::vector<unsigned char> file((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) throw InputError("failed while reading " + where);
    return parse_checkpoint(file, where);
}

Checkpoint parse_checkpoint(const std::vector<unsigned char>& file, const std::string& where) {
    // The first line: magic and version.
    const std::size_t magic_length = std::strlen(kMagic);
    std::size_t line_end = 0;
    while (line_end < file.size() && line_end < 64 && file[line_end] != '\n') ++line_end;
    const std::string first_line(file.begin(), file.begin() + static_cast<std::ptrdiff_t>(line_end));
    if (line_end >= file.size() || first_line.compare(0, magic_length, kMagic) != 0)
        throw InputError(where + " is not a Meltwater checkpoint (it does not start with \"" + kMagic + "\")");
    const std::string version = first_line.substr(magic_length);
    if (version != std::to_string(kFormatVersion))
        throw InputError(where + " has format version " + version + "; this build reads version " +
                         std::to_string(kFormatVersion));
    std::size_t at = line_end + 1;

    // The header, then the blocks it announces, then the checksum: the sizes must add up exactly.
    if (file.size() < at + 8) throw InputError(where + " is truncated (it ends inside its header)");
    const std::uint64_t header_length = get_u64(file.data() + at);
    at += 8;
    if (header_length > file.size() - at) throw InputError(where + " is truncated (it ends inside its header)");
    const std::string header_text(file.begin() + static_cast<std::ptrdiff_t>(at),
                                  file.begin() + static_cast<std::ptrdiff_t>(at + header_length));
    const std::size_t header_at = at;
    at += header_length;

    Checkpoint c;
    std::vector<StateBlock> blocks;
    try {
        const SceneJson header = SceneJson::parse(header_text);
        if (header.at("format").get<std::string>() != "meltwater checkpoint")
            throw InputError(where + " has an unknown format name in its header");
        const auto real_bytes = header.at("real_bytes").get<std::uint64_t>();
        if (real_bytes != sizeof(Real))
            throw InputError(where + " was written by a build that simulates with " + std::to_string(real_bytes) +
                             "-byte reals; this build uses " + std::to_string(sizeof(Real)) +
                             " (MELTWATER_DOUBLE differs)");
        c.backend = header.at("backend").get<std::string>();
        c.step = header.at("step").get<long>();
        c.time = header.at("time").get<double>();
        c.next_frame_time = header.at("next_frame_time").get<double>();
        c.frame_times = header.at("frame_times").get<std::vector<double>>();
        c.scene = header.at("scene");
        for (const auto& b : header.at("blocks")) {
            StateBlock block;
            block.name = b.at("name").get<std::string>();
            block.element_bytes = b.at("element_bytes").get<std::uint64_t>();
            block.count = b.at("count").get<std::uint64_t>();
            if (block.element_bytes == 0 || block.element_bytes > 4096 ||
                block.count > (std::uint64_t(1) << 40) / block.element_bytes)
                throw InputError(where + " announces an implausible block '" + block.name + "'");
            blocks.push_back(std::move(block));
        }
    } catch (const SceneJson::exception& e) {
        throw InputError(where + " has a damaged header: " + e.what());
    }
    std::uint64_t payload = 0;
    for (const StateBlock& b : blocks) payload += b.count * b.element_bytes;
    const std::uint64_t expected = at + payload + 8;
    if (file.size() != expected)
        throw InputError(where + " is " + std::to_string(file.size()) + " bytes where its header announces " +
                         std::to_string(expected) + (file.size() < expected ? " (truncated)" : " (extra bytes)"));
    Fnv1a sum;
    sum.add(file.data() + header_at, header_length);
    sum.add(file.data() + at, payload);
    if (sum.hash != get_u64(file.data() + at + payload))
        throw InputError(where + " is damaged (its checksum does not match its contents)");
    for (StateBlock& b : blocks) {
        const std::size_t n = b.count * b.element_bytes;
        b.bytes.assign(file.begin() + static_cast<std::ptrdiff_t>(at), file.begin() + static_cast<std::ptrdiff_t>(at + n));
        at += n;
        c.state.add(std::move(b));
    }
    check_clock(c, where);
    return c;
}

}  // namespace mw
