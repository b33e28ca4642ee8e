"""What the fleet scripts (fleet_demo.py, fleet_bench.py, fleet_shard_bench.py, fleet_design_b.py)
share: a free TCP port for their own ROS master, waiting for it, a private roscore with the
processes started under it (RosGraph), stopping them, and a process's CPU time from /proc."""
import os
import signal
import socket
import subprocess
import time


def free_port():
    """A TCP port on 127.0.0.1 free at the time of the call."""
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def cpu_seconds(pid):
    """User + system CPU seconds of process `pid` so far."""
    with open("/proc/%d/stat" % pid) as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def wait_for_master(caller):
    """Waits (up to 20 s) until the ROS master of ROS_MASTER_URI answers `caller`."""
    import rosgraph
    for _ in range(100):
        try:
            rosgraph.Master(caller).getPid()
            return
        except Exception:
            time.sleep(0.2)


def stop_all(procs):
    """SIGINT to every process, newest first, as Ctrl-C would; killed after 10 s."""
    for p in reversed(procs):
        p.send_signal(signal.SIGINT)
    for p in reversed(procs):
        try:
            p.wait(timeout=10)
        except subprocess.TimeoutExpired:
            p.kill()
            p.wait()


class RosGraph:
    """A private roscore on a free port and the processes started under it; `caller` names the
    script to the master. Sets ROS_MASTER_URI in os.environ too, so that rospy and rosgraph in
    this process talk to it, and /use_sim_time to true."""

    def __init__(self, caller):
        self.env = dict(os.environ)
        self.env["ROS_MASTER_URI"] = "http://127.0.0.1:%d" % free_port()
        self.env["ROS_HOSTNAME"] = "127.0.0.1"
        self.env.pop("ROS_IP", None)
        self.procs = []
        self.start(["roscore", "-p", self.env["ROS_MASTER_URI"].rsplit(":", 1)[1]])
        os.environ.update(self.env)
        wait_for_master(caller)
        self.param("set", "/use_sim_time", "true")

    def param(self, *args):
        """rosparam ARGS against this graph's master."""
        subprocess.run(["rosparam"] + list(args), env=self.env, check=True)

    def start(self, args):
        """Starts ARGS under this graph's master, output discarded; kept in self.procs."""
        p = subprocess.Popen(args, env=self.env, stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL)
        self.procs.append(p)
        return p
