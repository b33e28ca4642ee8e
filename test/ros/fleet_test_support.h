// Child processes of the fleet's rostests (test_fleet_system.cpp, test_fleet_shards.cpp): started
// as from a distinct host, stopped as Ctrl-C would.
#ifndef WAVOG_MAPPING_TEST_ROS_FLEET_TEST_SUPPORT_H_
#define WAVOG_MAPPING_TEST_ROS_FLEET_TEST_SUPPORT_H_

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <string>
#include <vector>

namespace fleet_test {

/// Starts `args`; `host` non-empty: the child's ROS_HOSTNAME (and no ROS_IP: roscpp listens on
/// 127.0.0.1 only when ROS_IP is 127.*), as on a host of its own (see test/fleet.test).
inline pid_t spawn(const std::vector<std::string>& args, const std::string& host = "") {
  const pid_t pid = fork();
  if (pid == 0) {
    if (!host.empty()) {
      unsetenv("ROS_IP");
      setenv("ROS_HOSTNAME", host.c_str(), 1);
    }
    std::vector<char*> argv;
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execvp(argv[0], argv.data());
    _exit(127);
  }
  return pid;
}

/// True once child `pid` has exited (reaps it); does not wait.
inline bool exited(pid_t pid) {
  int status = 0;
  return waitpid(pid, &status, WNOHANG) == pid;
}

/// SIGINT to child `pid` (none if pid <= 0), SIGKILL if it has not exited within 10 s; reaps it.
inline void stop(pid_t pid) {
  if (pid <= 0) return;
  kill(pid, SIGINT);
  for (int i = 0; i < 100; ++i) {
    if (exited(pid)) return;
    usleep(100000);
  }
  kill(pid, SIGKILL);
  waitpid(pid, nullptr, 0);
}

}  // namespace fleet_test

#endif  // WAVOG_MAPPING_TEST_ROS_FLEET_TEST_SUPPORT_H_
