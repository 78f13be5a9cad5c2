// MPI evaluation farm: rank 0 owns the work list and the results; every rank, rank 0's own
// evaluation thread included, evaluates. Tasks are handed out one at a time to whichever evaluator is free
// (runs differ in length), each result comes back with its task index and lands at that index, so what
// the caller assembles depends neither on the number of ranks nor on timing.
//
// Messages are arrays of doubles (exact bits; an index travels as a double, exact below 2^53). The farm
// knows nothing of PSO or benchmarks: a task is request(i) -> compute(request) -> reply(i, result), and
// compute is the same function on every rank (the core's evaluation), so the numbers are those of the
// threaded path.
//
// Without an MPI launcher (no mpirun/srun environment) the Farm is inactive and MPI is never initialised:
// the programs run on threads as before.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace sowing_robot {
namespace farm {

using Payload = std::vector<double>;
using Compute = std::function<Payload(const Payload& request)>;

/// Whether an MPI launcher started this process (Open MPI's mpirun, MPICH/Hydra or Slurm PMI/PMIx).
bool launchedByMpi();

class Farm {
 public:
  /// Initialises MPI (thread level funneled) if launchedByMpi(), else stays inactive (size 1, rank 0).
  /// Throws std::runtime_error if MPI cannot start.
  Farm(int* argc, char*** argv);
  /// Finalises MPI (rank 0 first releases the workers if stop() was not called).
  ~Farm();
  Farm(const Farm&) = delete;
  Farm& operator=(const Farm&) = delete;

  bool active() const { return active_; }
  int rank() const { return rank_; }
  int size() const { return size_; }
  bool root() const { return rank_ == 0; }
  /// "mpi 4 ranks on 2 hosts" or "threads" (no MPI).
  std::string describe() const;

  /// Rank 0: tasks 0..n-1, task i sent as request(i) to a free worker rank or run by rank 0's own
  /// evaluation thread (compute); reply(i, result) is called on the calling thread, in completion order.
  /// A worker's failure (its exception text) is rethrown here as std::runtime_error naming the rank.
  void run(int n, const std::function<Payload(int)>& request, const Compute& compute,
           const std::function<void(int, const Payload&)>& reply);
  /// Workers (rank > 0): evaluate what rank 0 sends until stop(); an exception in compute is sent to rank
  /// 0 as text (rank 0 reports it) and serve returns false. true on a normal stop.
  bool serve(const Compute& compute);
  /// Rank 0: releases the workers from serve(). Idempotent.
  void stop();
  /// Ends every rank of the job at once (MPI_Abort) after rank 0 printed why; inactive: exit(code).
  [[noreturn]] void abort(int code);
  /// Seconds rank 0 spent on the farm's own work in run() (sending, receiving, bookkeeping), excluding
  /// waiting for results: the overhead figure.
  double overheadSeconds() const { return overhead_s_; }
  /// Seconds of evaluation (compute) summed over all evaluators in run(), as each measured it.
  double evaluationSeconds() const { return evaluation_s_; }

 private:
  bool active_ = false;
  bool stopped_ = false;
  int rank_ = 0, size_ = 1;
  double overhead_s_ = 0.0, evaluation_s_ = 0.0;
};

}  // namespace farm
}  // namespace sowing_robot
