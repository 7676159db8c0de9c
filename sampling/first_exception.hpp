// Exceptions out of OpenMP loops. An exception that leaves an OpenMP region terminates the
// process, so the body of a parallel loop runs through FirstException::run(): the first exception
// is kept, later iterations are skipped, and rethrow() raises it on the calling thread once the
// region has ended.
#pragma once
#include <atomic>
#include <exception>

namespace mw {

class FirstException {
public:
    template <class Body>
    void run(Body&& body) noexcept {
        if (failed_.load(std::memory_order_relaxed)) return;
        try {
            body();
        } catch (...) {
#pragma omp critical(mw_sampling_first_exception)
            if (!first_) first_ = std::current_exception();
            failed_.store(true, std::memory_order_relaxed);
        }
    }
    void rethrow() const {
        if (first_) std::rethrow_exception(first_);
    }

private:
    std::atomic<bool> failed_{false};
    std::exception_ptr first_;
};

}  // namespace mw
