// The state a simulation carries from one step to the next, as named arrays on the host: what a
// checkpoint holds (apps/checkpoint_file.cpp puts it in a file). Plain host data with no backend
// type, so that a state saved on one backend loads on the other.
//
// Each block is a name ("store.position", "solids.rotation", "time"), the size of one element
// and the raw bytes. Loading checks both: a block that is missing, or whose elements have another
// size (a build with double Real, a changed struct), is refused with its name, never reinterpreted.
#pragma once
#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "common/errors.hpp"

namespace mw {

struct StateBlock {
    std::string name;
    std::uint64_t element_bytes = 0;
    std::uint64_t count = 0;
    std::vector<unsigned char> bytes;  // count * element_bytes
};

class StateArchive {
   public:
    template <class T>
    void put(const std::string& name, const std::vector<T>& values) {
        static_assert(std::is_trivially_copyable_v<T>, "state blocks hold plain data");
        StateBlock block;
        block.name = name;
        block.element_bytes = sizeof(T);
        block.count = values.size();
        block.bytes.resize(values.size() * sizeof(T));
        if (!values.empty()) std::memcpy(block.bytes.data(), values.data(), block.bytes.size());
        add(std::move(block));
    }
    template <class T>
    void put_value(const std::string& name, const T& value) {
        put(name, std::vector<T>{value});
    }

    // The block's elements; throws InputError naming the block if it is missing or its element
    // size is not sizeof(T).
    template <class T>
    std::vector<T> get(const std::string& name) const {
        const StateBlock& block = require(name);
        if (block.element_bytes != sizeof(T))
            throw InputError("checkpoint: block '" + name + "' has " + std::to_string(block.element_bytes) +
                             "-byte elements, this build expects " + std::to_string(sizeof(T)) +
                             " (written by a build with another precision or version?)");
        std::vector<T> values(block.count);
        if (block.count) std::memcpy(values.data(), block.bytes.data(), block.bytes.size());
        return values;
    }
    template <class T>
    T get_value(const std::string& name) const {
        const std::vector<T> values = get<T>(name);
        if (values.size() != 1)
            throw InputError("checkpoint: block '" + name + "' holds " + std::to_string(values.size()) +
                             " values, expected one");
        return values[0];
    }
    // As get(), and the count must be `count` (an array sized by the scene).
    template <class T>
    std::vector<T> get_sized(const std::string& name, std::size_t count) const {
        std::vector<T> values = get<T>(name);
        if (values.size() != count)
            throw InputError("checkpoint: block '" + name + "' holds " + std::to_string(values.size()) +
                             " elements where the scene has " + std::to_string(count) +
                             "; the checkpoint was written for another scene or version");
        return values;
    }

    bool has(const std::string& name) const { return find(name) != nullptr; }
    const StateBlock* find(const std::string& name) const {
        for (const StateBlock& b : blocks_)
            if (b.name == name) return &b;
        return nullptr;
    }
    // Adds a whole block (the file reader); a second block of the same name is refused.
    void add(StateBlock block) {
        if (block.bytes.size() != block.count * block.element_bytes)
            throw InputError("checkpoint: block '" + block.name + "' has " + std::to_string(block.bytes.size()) +
                             " bytes, not count x element size");
        if (has(block.name)) throw InputError("checkpoint: block '" + block.name + "' appears twice");
        blocks_.push_back(std::move(block));
    }
    const std::vector<StateBlock>& blocks() const { return blocks_; }

   private:
    const StateBlock& require(const std::string& name) const {
        const StateBlock* block = find(name);
        if (!block)
            throw InputError("checkpoint: no block '" + name +
                             "'; the checkpoint was written for another scene or by another version");
        return *block;
    }
    std::vector<StateBlock> blocks_;
};

}  // namespace mw
