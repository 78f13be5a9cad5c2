#include "sowing_robot/farm/farm.h"

// The C API only: Open MPI's deprecated C++ bindings do not compile warning-free.
#define OMPI_SKIP_MPICXX 1
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>

#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace sowing_robot {
namespace farm {

namespace {

enum Tag : int { kTask = 1, kResult = 2, kStop = 3, kError = 4 };

/// How long a waiting rank sleeps between two looks at its messages. MPI's blocking receive spins a core
/// while it waits, which an oversubscribed or shared machine cannot spare; a result is ready after
/// milliseconds of simulation, so 100 us of latency is noise.
constexpr auto kPoll = std::chrono::microseconds(100);

using Clock = std::chrono::steady_clock;

double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

void send(const Payload& data, int to, int tag) {
  MPI_Send(data.data(), static_cast<int>(data.size()), MPI_DOUBLE, to, tag, MPI_COMM_WORLD);
}

/// The message `status` announced, received whole.
Payload receive(const MPI_Status& probed) {
  int count = 0;
  MPI_Get_count(&probed, MPI_DOUBLE, &count);
  Payload data(static_cast<std::size_t>(count));
  MPI_Recv(data.data(), count, MPI_DOUBLE, probed.MPI_SOURCE, probed.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  return data;
}

Payload task(int index, const Payload& request) {
  Payload m;
  m.reserve(request.size() + 1);
  m.push_back(static_cast<double>(index));
  m.insert(m.end(), request.begin(), request.end());
  return m;
}

/// Rank 0's own evaluator: one thread that computes the task it is given while the main thread talks MPI.
class LocalEvaluator {
 public:
  explicit LocalEvaluator(const Compute& compute) : compute_(compute), thread_([this] { loop(); }) {}
  ~LocalEvaluator() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      quit_ = true;
    }
    cv_.notify_one();
    thread_.join();
  }
  bool idle() {
    std::lock_guard<std::mutex> lock(mutex_);
    return !busy_ && !done_;
  }
  void give(int index, Payload request) {
    std::lock_guard<std::mutex> lock(mutex_);
    index_ = index;
    request_ = std::move(request);
    busy_ = true;
    cv_.notify_one();
  }
  /// true with the finished task's index and result (rethrows its exception).
  bool take(int& index, Payload& result) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!done_) return false;
    done_ = false;
    if (error_) {
      std::exception_ptr e = error_;
      error_ = nullptr;
      std::rethrow_exception(e);
    }
    index = index_;
    result = std::move(result_);
    return true;
  }

 private:
  void loop() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      cv_.wait(lock, [this] { return quit_ || busy_; });
      if (quit_) return;
      Payload request = std::move(request_);
      lock.unlock();
      Payload result;
      std::exception_ptr error;
      const auto t0 = Clock::now();
      try {
        result = compute_(request);
      } catch (...) {
        error = std::current_exception();
      }
      result.push_back(seconds(Clock::now() - t0));
      lock.lock();
      result_ = std::move(result);
      error_ = error;
      busy_ = false;
      done_ = true;
    }
  }

  const Compute& compute_;
  std::mutex mutex_;
  std::condition_variable cv_;
  int index_ = 0;
  Payload request_, result_;
  std::exception_ptr error_;
  bool busy_ = false, done_ = false, quit_ = false;
  std::thread thread_;  // last: starts once the members above exist
};

}  // namespace

bool launchedByMpi() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK", "PMI_RANK"}) {
    const char* s = std::getenv(v);
    if (s && *s) return true;
  }
  return false;
}

Farm::Farm(int* argc, char*** argv) {
  if (!launchedByMpi()) return;
  int provided = 0;
  if (MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS)
    throw std::runtime_error("MPI_Init_thread failed");
  active_ = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
}

Farm::~Farm() {
  if (!active_) return;
  stop();
  MPI_Finalize();
}

std::string Farm::describe() const {
  if (!active_) return "threads (no MPI launcher)";
  return "MPI, " + std::to_string(size_) + " rank" + (size_ == 1 ? "" : "s") + " (rank 0 and " +
         std::to_string(size_ - 1) + " worker" + (size_ == 2 ? "" : "s") + " evaluate, one evaluation each at a time)";
}

void Farm::stop() {
  if (!active_ || stopped_ || rank_ != 0) return;
  stopped_ = true;
  for (int w = 1; w < size_; ++w) send(Payload{}, w, kStop);
}

void Farm::abort(int code) {
  if (active_) MPI_Abort(MPI_COMM_WORLD, code);
  std::exit(code);
}

void Farm::run(int n, const std::function<Payload(int)>& request, const Compute& compute,
               const std::function<void(int, const Payload&)>& reply) {
  if (rank_ != 0) throw std::logic_error("Farm::run is rank 0's");
  if (n <= 0) return;
  LocalEvaluator local(compute);
  int next = 0, completed = 0;
  auto t_busy = Clock::duration::zero();
  auto t = Clock::now();
  for (int w = 1; w < size_ && next < n; ++w, ++next) send(task(next, request(next)), w, kTask);
  if (next < n) {
    local.give(next, request(next));
    ++next;
  }
  t_busy += Clock::now() - t;
  while (completed < n) {
    bool progress = false;
    t = Clock::now();
    if (active_ && size_ > 1) {
      int flag = 0;
      MPI_Status status;
      MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &status);
      if (flag) {
        progress = true;
        Payload m = receive(status);
        if (status.MPI_TAG == kError)
          throw std::runtime_error("rank " + std::to_string(status.MPI_SOURCE) +
                                   " failed: " + std::string(m.begin(), m.end()));
        if (status.MPI_TAG != kResult || m.size() < 2)
          throw std::runtime_error("rank " + std::to_string(status.MPI_SOURCE) + " sent an unexpected message");
        if (next < n) {  // keep the worker busy before bookkeeping
          send(task(next, request(next)), status.MPI_SOURCE, kTask);
          ++next;
        }
        evaluation_s_ += m.back();
        m.pop_back();
        const int index = static_cast<int>(m.front());
        reply(index, Payload(m.begin() + 1, m.end()));
        ++completed;
      }
    }
    int index = 0;
    Payload result;
    if (local.take(index, result)) {
      progress = true;
      if (next < n) {
        local.give(next, request(next));
        ++next;
      }
      evaluation_s_ += result.back();
      result.pop_back();
      reply(index, result);
      ++completed;
    }
    if (progress) {
      t_busy += Clock::now() - t;
    } else {
      std::this_thread::sleep_for(kPoll);
    }
  }
  overhead_s_ += seconds(t_busy);
}

bool Farm::serve(const Compute& compute) {
  if (!active_ || rank_ == 0) return true;
  for (;;) {
    int flag = 0;
    MPI_Status status;
    MPI_Iprobe(0, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &status);
    if (!flag) {
      std::this_thread::sleep_for(kPoll);
      continue;
    }
    Payload m = receive(status);
    if (status.MPI_TAG == kStop) return true;
    const auto t0 = Clock::now();
    Payload out;
    try {
      if (m.empty()) throw std::runtime_error("empty task");
      out = compute(Payload(m.begin() + 1, m.end()));
    } catch (const std::exception& e) {
      const std::string what = e.what();
      send(Payload(what.begin(), what.end()), 0, kError);
      return false;
    }
    Payload reply;
    reply.reserve(out.size() + 2);
    reply.push_back(m.front());
    reply.insert(reply.end(), out.begin(), out.end());
    reply.push_back(seconds(Clock::now() - t0));
    send(reply, 0, kResult);
  }
}

}  // namespace farm
}  // namespace sowing_robot
