"""What the fleet scripts (fleet_demo.py, fleet_bench.py, fleet_design_b.py) share: a free TCP
port for their own ROS master, waiting for it, stopping the processes they started, and a
process's CPU time from /proc."""
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
