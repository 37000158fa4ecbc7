// WorkerThreads: tasks run on threads that are parked and reused, a slot's task on the thread
// that last ran that slot.
#include "pixelgym/envs/vector/worker_threads.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

namespace pixelgym::vector {
namespace {

// Runs one task per slot at once and returns the id of the thread each ran on.
std::vector<std::thread::id> run_slots(int slots) {
  std::vector<std::thread::id> ids(static_cast<std::size_t>(slots));
  std::atomic<int> waiting{slots};
  std::vector<WorkerThreads::Task> tasks;
  for (int slot = 0; slot < slots; ++slot) {
    tasks.push_back(WorkerThreads::start(slot, [&ids, &waiting, slot] {
      ids[static_cast<std::size_t>(slot)] = std::this_thread::get_id();
      // Every task holds its thread until all have started: they run at once.
      waiting.fetch_sub(1);
      while (waiting.load() > 0) std::this_thread::yield();
    }));
  }
  for (auto& task : tasks) task.join();
  return ids;
}

TEST(WorkerThreadsTest, TasksRunOnThreadsThatAreReusedBySlot) {
  const std::vector<std::thread::id> first = run_slots(3);
  const int started = WorkerThreads::threads_started();
  EXPECT_GE(started, 3);
  for (int round = 0; round < 5; ++round) {
    EXPECT_EQ(run_slots(3), first) << "round " << round;
    // Fewer slots: the threads of those slots, and no new thread.
    EXPECT_EQ(run_slots(2), std::vector<std::thread::id>(first.begin(), first.begin() + 2));
  }
  EXPECT_EQ(WorkerThreads::threads_started(), started);
  for (const std::thread::id& id : first) EXPECT_NE(id, std::this_thread::get_id());
}

TEST(WorkerThreadsTest, JoinWaitsForTheTaskAndMovedTasksJoinOnce) {
  std::atomic<bool> ran{false};
  WorkerThreads::Task task = WorkerThreads::start(7, [&ran] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    ran = true;
  });
  WorkerThreads::Task moved = std::move(task);
  EXPECT_FALSE(task.joinable());  // NOLINT(bugprone-use-after-move): what a move leaves
  EXPECT_TRUE(moved.joinable());
  moved.join();
  EXPECT_TRUE(ran);
  EXPECT_FALSE(moved.joinable());
  moved.join();  // a no-op
}

}  // namespace
}  // namespace pixelgym::vector
