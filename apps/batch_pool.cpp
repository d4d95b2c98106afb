#include "apps/batch_pool.h"

#include <poll.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>

#include "apps/exit_codes.h"
#include "mesh/errors.h"
#include "mesh/json_text.h"

namespace mrsnake::cli {

namespace {

struct Worker {
  pid_t pid = -1;
  int fd = -1;
  std::string pending;
};

// Writes every byte of `text` to fd, or ends the worker.
void write_or_exit(int fd, const std::string& text) {
  for (std::size_t sent = 0; sent < text.size();) {
    const ssize_t n = write(fd, text.data() + sent, text.size() - sent);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) _exit(1);
    sent += static_cast<std::size_t>(n);
  }
}

// The worker process w: its images' rows, one JSON line each, on fd. Never returns.
[[noreturn]] void run_worker(int w, int jobs, std::size_t count, int read_fd, int write_fd,
                             const std::vector<Worker>& others, pid_t batch, const BatchRowFn& row) {
  // Nothing leaves this function: the worker ends with _exit, without the atexit handlers or
  // static destructors of the batch's state.
  try {
    close(read_fd);
    for (const Worker& other : others) close(other.fd);
    // Killed with the batch (its handler removes the temporaries), also if the batch died
    // before this line.
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != batch) _exit(1);
    for (std::size_t i = static_cast<std::size_t>(w); i < count; i += static_cast<std::size_t>(jobs))
      write_or_exit(write_fd, json_text({{"index", i}, {"row", row(i)}}) + "\n");
    close(write_fd);
  } catch (...) {
    _exit(1);
  }
  _exit(0);
}

// Forks worker w; the batch keeps the read end of its pipe.
Worker start_worker(int w, int jobs, std::size_t count, const std::vector<Worker>& others, const BatchRowFn& row) {
  int fds[2];
  if (pipe(fds) != 0) throw Error(std::string("cannot start a batch worker: pipe failed: ") + std::strerror(errno));
  const pid_t batch = getpid();
  const pid_t pid = fork();
  if (pid < 0) throw Error(std::string("cannot start a batch worker: fork failed: ") + std::strerror(errno));
  if (pid == 0) run_worker(w, jobs, count, fds[0], fds[1], others, batch, row);
  close(fds[1]);
  return {pid, fds[0], {}};
}

// Reads what the worker has sent and hands each complete line's row to `done`; false once its
// pipe is closed.
bool read_rows(Worker& worker, const std::vector<std::string>& images, const std::vector<std::string>& outputs,
               std::vector<bool>& reported, const std::function<void(std::size_t, nlohmann::json)>& done) {
  char buffer[65536];
  const ssize_t n = read(worker.fd, buffer, sizeof buffer);
  if (n < 0 && errno == EINTR) return true;
  if (n <= 0) {
    close(worker.fd);
    worker.fd = -1;
    return false;
  }
  worker.pending.append(buffer, static_cast<std::size_t>(n));
  for (std::size_t end; (end = worker.pending.find('\n')) != std::string::npos;) {
    const nlohmann::json message = nlohmann::json::parse(worker.pending.substr(0, end));
    worker.pending.erase(0, end + 1);
    const auto index = message["index"].get<std::size_t>();
    reported[index] = true;
    // The paths as given: the line's JSON text replaced any bytes that are not UTF-8.
    nlohmann::json row = message["row"];
    row["image"] = images[index];
    row["output"] = outputs[index];
    done(index, std::move(row));
  }
  return true;
}

// The row of an image whose worker stopped (exit `status` of waitpid) before segmenting it.
nlohmann::json stopped_worker_row(const std::string& image, const std::string& output, int status) {
  return {{"image", image},
          {"output", output},
          {"status", "failed"},
          {"error", "its batch worker stopped (" +
                        (WIFSIGNALED(status) ? "signal " + std::to_string(WTERMSIG(status))
                                             : "exit code " + std::to_string(WEXITSTATUS(status))) +
                        ") before segmenting it"},
          {"exit_code", static_cast<int>(ExitCode::internal)},
          {"wall_seconds", 0.0}};
}

}  // namespace

void run_batch_in_processes(int jobs, const std::vector<std::string>& images, const std::vector<std::string>& outputs,
                            const BatchRowFn& row, const std::function<void(std::size_t, nlohmann::json)>& done) {
  std::vector<Worker> workers;
  std::vector<bool> reported(images.size(), false);
  std::fflush(stdout);
  std::fflush(stderr);
  for (int w = 0; w < jobs && static_cast<std::size_t>(w) < images.size(); ++w)
    workers.push_back(start_worker(w, jobs, images.size(), workers, row));
  std::size_t open_pipes = workers.size();
  while (open_pipes > 0) {
    std::vector<pollfd> polled;
    for (const Worker& worker : workers)
      if (worker.fd >= 0) polled.push_back({worker.fd, POLLIN, 0});
    if (poll(polled.data(), polled.size(), -1) < 0) {
      if (errno == EINTR) continue;
      throw Error(std::string("batch workers: poll failed: ") + std::strerror(errno));
    }
    for (Worker& worker : workers) {
      if (worker.fd < 0) continue;
      const auto it = std::find_if(polled.begin(), polled.end(), [&](const pollfd& p) { return p.fd == worker.fd; });
      if (it == polled.end() || it->revents == 0) continue;
      if (!read_rows(worker, images, outputs, reported, done)) --open_pipes;
    }
  }
  // A worker that died (a crash, a kill) leaves its remaining images unreported.
  for (std::size_t w = 0; w < workers.size(); ++w) {
    int status = 0;
    while (waitpid(workers[w].pid, &status, 0) < 0 && errno == EINTR) {
    }
    for (std::size_t i = w; i < images.size(); i += workers.size())
      if (!reported[i]) done(i, stopped_worker_row(images[i], outputs[i], status));
  }
}

}  // namespace mrsnake::cli
