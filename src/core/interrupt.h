#pragma once
// A process-wide cancellation point for long work outside the render passes: scene loading and
// accelerator builds. The headless signal handler calls request_interrupt(); the loaders and
// builders call throw_if_interrupted() (or poll interrupt_requested() where an exception must not
// escape, as inside an OpenMP region) often enough that a stop takes well under a second.
#include <atomic>
#include <exception>

namespace candela {

// Thrown by throw_if_interrupted(). Deliberately not an Error: it is not bad input, and the
// loaders' `catch (const Error&)` (which add file names) must let it through untouched.
class Interrupted : public std::exception {
public:
    const char* what() const noexcept override { return "interrupted"; }
};

namespace detail {
// Constant-initialised and lock-free, so that a signal handler may set it.
inline std::atomic<bool> g_interrupt_requested{false};
static_assert(std::atomic<bool>::is_always_lock_free);
}  // namespace detail

// Async-signal-safe.
inline void request_interrupt() { detail::g_interrupt_requested.store(true, std::memory_order_relaxed); }
inline void clear_interrupt() { detail::g_interrupt_requested.store(false, std::memory_order_relaxed); }
// One relaxed load: cheap enough to poll per line of a file or per node of a tree.
inline bool interrupt_requested() { return detail::g_interrupt_requested.load(std::memory_order_relaxed); }
inline void throw_if_interrupted() {
    if (interrupt_requested()) throw Interrupted();
}

}  // namespace candela
