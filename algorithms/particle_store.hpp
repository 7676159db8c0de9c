// The particle store: every per-particle field as its own array (structure of arrays), all owned
// here, and one call that applies a permutation to every persistent field at once (the Cabana
// habit: no per-solver "remember to sort my field" hooks).
//
// Layout: [0, moving_count) particles that move and are re-sorted every step (fluid, SBPs, IBPs,
// GPs), then [moving_count, size) static boundary particles, sorted once at start-up. Particles
// may change type at run time (melting turns an SBP into fluid): type is data, not position.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "algorithms/state_archive.hpp"
#include "algorithms/vec3.hpp"
#include "backend/backend.hpp"

MW_BACKEND_BEGIN

// data[i] <- data[perm[i]] for i < perm.size(), through `gathered` (free function: nvcc does not
// allow device lambdas inside private nested classes).
template <class T>
void permute_in_place(const DeviceContext& device, T* data, View<const std::uint32_t> perm, T* gathered) {
    parallel_for(device, "store_permute_gather", perm.size(), [=] MW_HD(std::size_t i) { gathered[i] = data[perm[i]]; });
    parallel_for(device, "store_permute_copy", perm.size(), [=] MW_HD(std::size_t i) { data[i] = gathered[i]; });
}

// Persistent fields survive from step to step and are permuted with the particles; scratch
// fields are recomputed every step after the sort, so permuting them would waste bandwidth.
enum class FieldLife { kPersistent, kScratch };

class ParticleStore {
    struct Field;
    // Declared first: the registry must exist before the core fields below register in it.
    const DeviceContext& device_;
    std::vector<std::unique_ptr<Field>> fields_;
    DeviceArray<unsigned char> scratch_;  // one gather buffer shared by all fields
    std::size_t size_ = 0;
    std::size_t moving_count_ = 0;

   public:
    explicit ParticleStore(const DeviceContext& device)
        : device_(device),
          id(add<std::uint32_t>("id", FieldLife::kPersistent)),
          position(add<Vec3>("position", FieldLife::kPersistent)),
          velocity(add<Vec3>("velocity", FieldLife::kPersistent)),
          type(add<std::uint8_t>("type", FieldLife::kPersistent)),
          object(add<std::int32_t>("object", FieldLife::kPersistent)),
          density(add<Real>("density", FieldLife::kPersistent)),
          pressure(add<Real>("pressure", FieldLife::kScratch)) {}

    ParticleStore(const ParticleStore&) = delete;
    ParticleStore& operator=(const ParticleStore&) = delete;

    // Registers a new per-particle field (sized like the store). Modules (solids, heat, melting,
    // the neighbour lists) add their own fields this way; the reference stays valid for the
    // store's life. `may_be_absent`: a checkpoint without it loads, and leaves it to its module
    // (which rebuilds it from its initial value).
    template <class T>
    DeviceArray<T>& add(const char* name, FieldLife life, bool may_be_absent = false) {
        auto field = std::make_unique<TypedField<T>>(name, life);
        field->may_be_absent = may_be_absent;
        field->array.resize(size_);
        DeviceArray<T>& array = field->array;
        fields_.push_back(std::move(field));
        return array;
    }

    // The field registered as `name` with element type T, or null: how one module reads another's
    // field (melting and emitters the heat's temperatures).
    template <class T>
    DeviceArray<T>* find(const char* name) {
        for (auto& f : fields_)
            if (f->name == name)
                if (auto* typed = dynamic_cast<TypedField<T>*>(f.get())) return &typed->array;
        return nullptr;
    }

    void resize(std::size_t count, std::size_t moving_count) {
        size_ = count;
        moving_count_ = moving_count;
        for (auto& f : fields_) f->resize(count);
    }
    std::size_t size() const { return size_; }
    std::size_t moving_count() const { return moving_count_; }
    std::size_t static_count() const { return size_ - moving_count_; }
    const DeviceContext& device() const { return device_; }

    // Reorders particles [first, first + perm.size()): new slot i takes the particle that was at
    // first + perm[i]. Persistent fields only.
    void permute(View<const std::uint32_t> perm, std::size_t first) {
        for (auto& f : fields_)
            if (f->life == FieldLife::kPersistent) f->permute(device_, perm, first, scratch_);
    }

    // Checkpoints (state_archive.hpp): every persistent field as block "store.NAME", in the
    // store's current order, and the two counts. Scratch fields are recomputed by the next step.
    void save(StateArchive& archive) const {
        archive.put_value<std::uint64_t>("store.size", size_);
        archive.put_value<std::uint64_t>("store.moving_count", moving_count_);
        for (const auto& f : fields_)
            if (f->life == FieldLife::kPersistent) f->save(archive, "store." + f->name);
    }
    // Loads what save() wrote into a store built for the same scene (same size and layout). Every
    // persistent field must be in the archive, but those registered as `may_be_absent`.
    void load(const StateArchive& archive) {
        check_counts(archive);
        for (auto& f : fields_) {
            if (f->life != FieldLife::kPersistent) continue;
            const std::string name = "store." + f->name;
            if (f->may_be_absent && !archive.has(name)) continue;
            f->load(archive, name, size_);
        }
    }
    // Throws InputError unless the archive's store has this one's size and moving count.
    void check_counts(const StateArchive& archive) const {
        const auto size = archive.get_value<std::uint64_t>("store.size");
        const auto moving = archive.get_value<std::uint64_t>("store.moving_count");
        if (size != size_ || moving != moving_count_)
            throw InputError("checkpoint: holds " + std::to_string(size) + " particles (" + std::to_string(moving) +
                             " moving) where the scene builds " + std::to_string(size_) + " (" +
                             std::to_string(moving_count_) + " moving); it was written for another scene");
    }

    std::size_t bytes() const {
        std::size_t total = scratch_.bytes();
        for (const auto& f : fields_) total += f->bytes();
        return total;
    }

    DeviceArray<std::uint32_t>& id;  // the particle's index in the scene's initial list
    DeviceArray<Vec3>& position;
    DeviceArray<Vec3>& velocity;
    DeviceArray<std::uint8_t>& type;
    DeviceArray<std::int32_t>& object;
    DeviceArray<Real>& density;   // persistent: the last predicted density seeds viscosity
    DeviceArray<Real>& pressure;  // recomputed from zero every step

   private:
    struct Field {
        Field(const char* field_name, FieldLife field_life) : name(field_name), life(field_life) {}
        virtual ~Field() = default;
        virtual void resize(std::size_t n) = 0;
        virtual std::size_t bytes() const = 0;
        virtual void permute(const DeviceContext& device, View<const std::uint32_t> perm, std::size_t first,
                             DeviceArray<unsigned char>& scratch) = 0;
        virtual void save(StateArchive& archive, const std::string& block) const = 0;
        virtual void load(const StateArchive& archive, const std::string& block, std::size_t count) = 0;
        std::string name;
        FieldLife life;
        bool may_be_absent = false;
    };
    template <class T>
    struct TypedField final : Field {
        using Field::Field;
        DeviceArray<T> array;
        void resize(std::size_t n) override { array.resize(n); }
        std::size_t bytes() const override { return array.bytes(); }
        void permute(const DeviceContext& device, View<const std::uint32_t> perm, std::size_t first,
                     DeviceArray<unsigned char>& scratch) override {
            const std::size_t n = perm.size();
            scratch.resize(n * sizeof(T));
            permute_in_place(device, array.view().data() + first, perm, reinterpret_cast<T*>(scratch.view().data()));
        }
        void save(StateArchive& archive, const std::string& block) const override {
            archive.put(block, array.to_host());
        }
        void load(const StateArchive& archive, const std::string& block, std::size_t count) override {
            array.upload(archive.get_sized<T>(block, count));
        }
    };

};

MW_BACKEND_END
