// Runs a shell command from a rostest (the node started with bad parameters, to check that it
// refuses them): its exit status and everything it printed.
#ifndef WAVOG_MAPPING_TEST_ROS_RUN_COMMAND_H_
#define WAVOG_MAPPING_TEST_ROS_RUN_COMMAND_H_

#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace room {

/// Runs `command`, returns its exit status (-1 if it did not exit normally); *output gets its
/// stdout and stderr.
inline int run(const std::string& command, std::string* output) {
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return -1;
  char buffer[4096];
  while (fgets(buffer, sizeof(buffer), pipe)) *output += buffer;
  const int status = pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace room

#endif  // WAVOG_MAPPING_TEST_ROS_RUN_COMMAND_H_
