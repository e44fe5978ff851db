#pragma once

#include <cstddef>
#include <functional>

// Work in a fixed order whose expensive part does not depend on the order: a
// pipeline that prepares items ahead on every OpenMP thread while the calling
// thread consumes them one after another (issue 33: each face's placement search
// reads only the photos, so the faces ahead are searched while the calling thread
// places and corrects the faces in their breadth-first order).
namespace texlume {

/// How many threads RunAhead's prepare may run on here: its `worker` argument is
/// below this (omp_get_max_threads(), or 1 within a parallel region).
std::size_t RunAheadWorkers();

/// Runs prepare(i, worker) for every i in [0, count) on any thread of an OpenMP
/// team (`worker` < RunAheadWorkers(): no two calls at once share one), and
/// consume(i) on the calling thread in the order 0, 1, 2, ...; consume(i) starts
/// after prepare(i) has returned. prepare(i) starts only once consume(i - window)
/// has returned, so the caller may keep what prepare leaves for consume in
/// `window` slots (slot i % window). The calling thread prepares too while the item
/// it needs next is not prepared yet. With one thread (or one item), prepare(i)
/// then consume(i), in turn. An exception ends the run as in that turn: the one of
/// the first failure in the order prepare(0), consume(0), prepare(1), ... is
/// rethrown on the calling thread once every thread has stopped, whichever thread
/// met its failure first, and no item past a failed one starts. prepare must be
/// safe to run on several threads at once.
/// `window` >= 1.
void RunAhead(std::size_t count, std::size_t window,
              const std::function<void(std::size_t item, std::size_t worker)>& prepare,
              const std::function<void(std::size_t item)>& consume);

}  // namespace texlume
