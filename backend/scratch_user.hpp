// Who holds the backend's shared scratch (backend_scratch_bytes: the sort's buffers, kept between
// calls and counted by no DeviceArray owner). Every simulation holds a ScratchUser; when the last
// one is destroyed the backend frees that scratch (release_backend_scratch), so that the next
// simulation's memory figure is its own and not the largest of the process so far (a benchmark
// runs cases from 7k to 4M particles in turn). Backend-agnostic: included by backend/backend.hpp
// after the backend, and so compiled into that backend's namespace.
#pragma once
#include <atomic>

MW_BACKEND_BEGIN

class ScratchUser {
   public:
    ScratchUser() { ++users(); }
    ~ScratchUser() {
        if (--users() == 0) release_backend_scratch();
    }
    ScratchUser(const ScratchUser&) = delete;
    ScratchUser& operator=(const ScratchUser&) = delete;

   private:
    static std::atomic<int>& users() {
        static std::atomic<int> count{0};
        return count;
    }
};

MW_BACKEND_END
