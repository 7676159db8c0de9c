// The neighbour search's parameters (neighbor_search.hpp), scene section `neighbors`. Host-only.
#pragma once
#include "simulation/parameters.hpp"

namespace mw {

enum class CellOrdering { kLinear, kZOrder };

struct NeighborParams {
    CellOrdering ordering = CellOrdering::kZOrder;  // of the grid's cells, and so of the particles in memory
    int cells_per_support = 1;                      // grid cell size = h / this (1 or 2)
    // Per-step neighbour lists for the fluid's gathers, or gathering from the grid every time.
    // kAuto takes the backend's preference (lists on OpenMP, grid on CUDA).
    enum class Lists { kAuto, kOn, kOff } lists = Lists::kAuto;
};

inline const ParamTable<NeighborParams>& neighbor_keys() {
    using T = NeighborParams;
    static const ParamTable<T> table = [] {
        ParamTable<T> t;
        t.push_back(choice_key<T, CellOrdering>("neighbors", "ordering", member(&T::ordering),
                                                {{"zorder", CellOrdering::kZOrder}, {"linear", CellOrdering::kLinear}},
                                                "the order of the grid's cells, and so of the particles in memory"));
        t.push_back(integer_key<T>("neighbors", "cells_per_support", member(&T::cells_per_support), 1, 2,
                                   "grid cells per support radius"));
        t.push_back(choice_key<T, T::Lists>(
            "neighbors", "lists", member(&T::lists),
            {{"auto", T::Lists::kAuto}, {"on", T::Lists::kOn}, {"off", T::Lists::kOff}},
            "per-step neighbour lists for the fluid; auto: on for OpenMP, off for CUDA (docs/solver.md)"));
        return t;
    }();
    return table;
}

}  // namespace mw
