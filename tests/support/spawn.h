#pragma once
// Runs the candela program in the background, for tests that signal or kill it part-way.
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <chrono>
#include <string>
#include <thread>

namespace candela::test {

// `candela args` running in the background with stdout and stderr going to a log file. The shell
// execs env, which execs candela, so `pid` is candela's own: a signal sent to it reaches the
// renderer. `program` replaces candela (the MPI tests run mpirun, whose args name candela).
class Child {
public:
    Child(const std::string& args, const std::string& log, const std::string& program = CANDELA_BIN) {
        std::string cmd = std::string("exec env -u DISPLAY -u WAYLAND_DISPLAY ") + program + " " + args + " >'" +
                          log + "' 2>&1";
        pid_ = fork();
        if (pid_ == 0) {
            execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
            _exit(127);
        }
    }
    ~Child() {
        if (running()) {
            kill(pid_, SIGKILL);
            wait(60);
        }
    }
    Child(const Child&) = delete;
    Child& operator=(const Child&) = delete;

    pid_t pid() const { return pid_; }
    void signal(int sig) const { kill(pid_, sig); }
    // Reaps the child if it has exited.
    bool running() {
        if (code_ != kRunning || pid_ <= 0) return false;
        int status = 0;
        pid_t r = waitpid(pid_, &status, WNOHANG);
        if (r == pid_) code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        else if (r < 0) code_ = -1;
        return code_ == kRunning;
    }
    // Exit code, 128 + the signal that killed it, or -1 if it did not end within `timeout_s`
    // seconds (it is then killed).
    int wait(double timeout_s = 600) {
        auto t0 = std::chrono::steady_clock::now();
        while (running()) {
            if (std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() > timeout_s) {
                kill(pid_, SIGKILL);
                int status;
                waitpid(pid_, &status, 0);
                code_ = -1;
                break;
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        }
        return code_;
    }
    // Polls until `pred()` holds (true), or the child ends or `timeout_s` passes (false).
    template <class Pred>
    bool wait_until(Pred pred, double timeout_s = 300) {
        auto t0 = std::chrono::steady_clock::now();
        while (std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() < timeout_s) {
            if (pred()) return true;
            if (!running()) return pred();
            std::this_thread::sleep_for(std::chrono::milliseconds(2));
        }
        return false;
    }

private:
    static constexpr int kRunning = -2;
    pid_t pid_ = -1;
    int code_ = kRunning;
};

inline bool file_exists(const std::string& path) {
    struct stat st;
    return stat(path.c_str(), &st) == 0;
}

}  // namespace candela::test
