#pragma once
// A PostgreSQL server of the test's own (Debian's postgresql, as scripts/setup installs it):
// initdb in a temporary directory, then `postgres` on 127.0.0.1 at a free port, as a
// separate process, stopped (and its directory removed) when the object goes. PostgreSQL
// refuses to run as root: as root, both run as the `postgres` user Debian's package creates
// (not as hybridctl-cnc, whose processes the LinuxCNC tests take for another LinuxCNC). Missing binaries or a server that does not start fail loudly.

#include <netinet/in.h>
#include <grp.h>
#include <pwd.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <libpq-fe.h>

namespace hybridctl::cell::testing {

class PostgresServer {
 public:
  PostgresServer() {
    bin_ = find_bin();
    char pattern[] = "/tmp/hybridctl-cell-pg-XXXXXX";
    if (!mkdtemp(pattern)) throw std::runtime_error("cannot make the server's directory");
    dir_ = pattern;
    if (geteuid() == 0) {
      const passwd* pw = getpwnam(kUser);
      if (!pw)
        throw std::runtime_error(std::string("no user ") + kUser + ": run scripts/setup (it installs postgresql, which makes it; "
                                 "PostgreSQL will not run as root)");
      user_ = kUser;
      std::filesystem::permissions(dir_, std::filesystem::perms::owner_all);
      if (chown(dir_.c_str(), pw->pw_uid, pw->pw_gid) != 0) throw std::runtime_error("cannot give the server's directory to " + user_);
    }
    port_ = free_port();
    run({bin_ + "/initdb", "-D", (dir_ / "data").string(), "-U", "cell", "--auth=trust", "-E", "UTF8", "--no-sync"},
        (dir_ / "initdb.log").string());
    start();
  }
  ~PostgresServer() {
    stop();
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  PostgresServer(const PostgresServer&) = delete;
  PostgresServer& operator=(const PostgresServer&) = delete;

  std::string uri(const std::string& database = "postgres") const {
    return "postgresql://cell@127.0.0.1:" + std::to_string(port_) + "/" + database;
  }
  int port() const { return port_; }

  // Starts the server and waits until it accepts connections.
  void start() {
    pid_ = spawn({bin_ + "/postgres", "-D", (dir_ / "data").string(), "-h", "127.0.0.1", "-p", std::to_string(port_), "-k",
                  dir_.string(), "-F", "-c", "max_connections=60"},
                 (dir_ / "server.log").string());
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (PQping(uri().c_str()) != PQPING_OK) {
      int status = 0;
      if (waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        throw std::runtime_error("PostgreSQL did not start; see " + (dir_ / "server.log").string());
      }
      if (std::chrono::steady_clock::now() > deadline) throw std::runtime_error("PostgreSQL did not answer within 60 s");
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }
  // Fast shutdown (SIGINT: connections are cut, as on a database restart).
  void stop() {
    if (pid_ <= 0) return;
    kill(pid_, SIGINT);
    int status = 0;
    waitpid(pid_, &status, 0);
    pid_ = -1;
  }

 private:
  static constexpr const char* kUser = "postgres";

  static std::string find_bin() {
    for (int v = 20; v >= 12; --v) {
      const std::string dir = "/usr/lib/postgresql/" + std::to_string(v) + "/bin";
      if (std::filesystem::exists(dir + "/postgres") && std::filesystem::exists(dir + "/initdb")) return dir;
    }
    throw std::runtime_error("no PostgreSQL server under /usr/lib/postgresql/*/bin: run scripts/setup (it installs postgresql)");
  }
  static int free_port() {
    const int s = socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t len = sizeof a;
    if (bind(s, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 || getsockname(s, reinterpret_cast<sockaddr*>(&a), &len) != 0)
      throw std::runtime_error("cannot find a free port on 127.0.0.1");
    close(s);
    return ntohs(a.sin_port);
  }
  // args[0] run as the server's user (its pid is the server's: signals reach it directly).
  pid_t spawn(std::vector<std::string> args, const std::string& log) const {
    const passwd* pw = user_.empty() ? nullptr : getpwnam(user_.c_str());
    const pid_t pid = fork();
    if (pid < 0) throw std::runtime_error("cannot fork");
    if (pid == 0) {
      if (pw && (setgroups(0, nullptr) != 0 || setgid(pw->pw_gid) != 0 || setuid(pw->pw_uid) != 0)) _exit(126);
      // Its own directory as the working one: the user may not enter the test's (a clone under /root).
      if (chdir(dir_.c_str()) != 0) _exit(126);
      FILE* out = std::fopen(log.c_str(), "w");
      if (out) dup2(fileno(out), 1), dup2(fileno(out), 2);
      std::vector<char*> argv;
      for (std::string& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      execv(argv[0], argv.data());
      _exit(127);
    }
    return pid;
  }
  void run(const std::vector<std::string>& args, const std::string& log) const {
    int status = 0;
    waitpid(spawn(args, log), &status, 0);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) throw std::runtime_error(args[0] + " failed; see " + log);
  }

  std::string bin_, user_;
  std::filesystem::path dir_;
  int port_ = 0;
  pid_t pid_ = -1;
};

}  // namespace hybridctl::cell::testing
