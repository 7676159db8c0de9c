#include "sampling/lattice_sampler.hpp"

namespace mw {

InnerParticles sample_inner(const TriangleMesh& mesh, double spacing, const InsideOutsideOptions& options) {
    InnerParticles out;
    out.grid = make_lattice_grid(bounding_box(mesh), spacing);
    const LatticeGrid& g = out.grid;
    out.classification = classify_lattice(mesh, g, options);
    const std::vector<std::uint8_t>& inside = out.classification.inside;

    // Lattice index -> IBP index (-1 outside), IBPs numbered in lattice order (x fastest).
    std::vector<int> ibp_of(g.count(), -1);
    int count = 0;
    for (std::size_t id = 0; id < g.count(); ++id)
        if (inside[id]) ibp_of[id] = count++;
    out.positions.resize(static_cast<std::size_t>(count));
    out.lattice.resize(static_cast<std::size_t>(count));
    for (int k = 0; k < g.dims[2]; ++k)
        for (int j = 0; j < g.dims[1]; ++j)
            for (int i = 0; i < g.dims[0]; ++i) {
                const int p = ibp_of[g.index(i, j, k)];
                if (p < 0) continue;
                out.positions[static_cast<std::size_t>(p)] = g.position(i, j, k);
                out.lattice[static_cast<std::size_t>(p)] = {i, j, k};
            }

    // One-ring connectivity, offsets first, then indices; neighbours in (dk, dj, di) order are in
    // increasing IBP index order because IBPs are numbered in lattice order.
    out.neighbor_offsets.assign(static_cast<std::size_t>(count) + 1, 0);
    auto for_neighbours = [&](int p, auto&& visit) {
        const auto c = out.lattice[static_cast<std::size_t>(p)];
        for (int dk = -1; dk <= 1; ++dk)
            for (int dj = -1; dj <= 1; ++dj)
                for (int di = -1; di <= 1; ++di) {
                    if (!di && !dj && !dk) continue;
                    const int i = c[0] + di, j = c[1] + dj, k = c[2] + dk;
                    if (!g.contains(i, j, k)) continue;
                    const int q = ibp_of[g.index(i, j, k)];
                    if (q >= 0) visit(q);
                }
    };
#pragma omp parallel for schedule(static)
    for (int p = 0; p < count; ++p) {
        int n = 0;
        for_neighbours(p, [&](int) { ++n; });
        out.neighbor_offsets[static_cast<std::size_t>(p) + 1] = n;
    }
    for (int p = 0; p < count; ++p) out.neighbor_offsets[p + 1] += out.neighbor_offsets[p];
    out.neighbor_indices.resize(static_cast<std::size_t>(out.neighbor_offsets[count]));
#pragma omp parallel for schedule(static)
    for (int p = 0; p < count; ++p) {
        int at = out.neighbor_offsets[static_cast<std::size_t>(p)];
        for_neighbours(p, [&](int q) { out.neighbor_indices[static_cast<std::size_t>(at++)] = q; });
    }
    out.classification.inside.clear();
    out.classification.inside.shrink_to_fit();
    return out;
}

}  // namespace mw
