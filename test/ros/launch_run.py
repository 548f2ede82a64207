"""One roslaunch of a dem_mobility launch file as a user starts it, with its own master on a free
port and its own folder (ROS_HOME, the log, the bag and the result YAML beside it): what the
end-to-end tests under test/ros share."""
import os
import signal
import subprocess
import time

import rosbag
import yaml

from dem_mobility_tools.runs import free_port  # noqa: F401 (the tests beside this file take it from here)


def stop_group(proc, timeout=20):
    """Ends a process started in a session of its own together with its children (a roslaunch
    with its master and nodes): SIGINT, as Ctrl-C, then SIGKILL after `timeout` s."""
    if proc.poll() is not None:
        return
    os.killpg(proc.pid, signal.SIGINT)
    try:
        proc.wait(timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()


class LaunchRun:
    """`roslaunch dem_mobility LAUNCH bag:=DIR/run.bag ARGS...` in DIR = tmp/name; the run's result
    YAML is the bag's name with .result.yaml. `env` adds to the environment; `prefix` goes before
    roslaunch on its command line (e.g. prlimit and its limits); `program`: roslaunch, or the argv
    of dm-launch (roslaunch with the run's exit status)."""

    def __init__(self, tmp, name, launch, *args, env=None, prefix=(), program='roslaunch'):
        self.dir = os.path.join(tmp, name)
        os.makedirs(self.dir)
        self.bag = os.path.join(self.dir, 'run.bag')
        self.result_file = self.bag[:-4] + '.result.yaml'
        self.port = free_port()
        env = dict(os.environ, ROS_HOME=self.dir, ROS_MASTER_URI='http://localhost:%d' % self.port, **(env or {}))
        self.env = {k: v for k, v in env.items() if v is not None}  # (None: the variable unset)
        self.log = open(os.path.join(self.dir, 'roslaunch.log'), 'w')
        program = [program] if isinstance(program, str) else list(program)
        self.proc = subprocess.Popen(list(prefix) + program + ['-p', str(self.port), 'dem_mobility', launch,
                                      'bag:=' + self.bag] + list(args),
                                     stdout=self.log, stderr=subprocess.STDOUT, env=self.env,
                                     start_new_session=True)

    def wait(self, timeout):
        """Waits for roslaunch to end (killing its process group after `timeout` s: an error)."""
        try:
            self.proc.wait(timeout)
        except subprocess.TimeoutExpired:
            os.killpg(self.proc.pid, signal.SIGKILL)
            raise AssertionError('roslaunch did not end within %d s (log %s)' % (timeout, self.log.name))
        finally:
            self.log.close()
        return self

    def stop(self, sig, group=True, timeout=60):
        """Sends `sig` to roslaunch's process group (as Ctrl-C does) or, `group` false, to roslaunch
        alone, and waits for the end; returns the seconds from the signal to the result file's last
        write (the run's own stop, before roslaunch takes the master down)."""
        t0 = time.time()
        if group:
            os.killpg(self.proc.pid, sig)
        else:
            os.kill(self.proc.pid, sig)
        self.wait(timeout)
        return os.path.getmtime(self.result_file) - t0

    def bag_info(self):
        """`rosbag info` of the bag: (return code, its output); a bag left open says 'unindexed'."""
        p = subprocess.run(['rosbag', 'info', self.bag], capture_output=True, text=True, env=self.env)
        return p.returncode, p.stdout + p.stderr

    @property
    def returncode(self):
        return self.proc.returncode

    def output(self):
        with open(self.log.name) as f:
            return f.read()

    def result(self):
        with open(self.result_file) as f:
            return yaml.safe_load(f)

    def messages(self, topics=None, raw=False):
        """(topic, message, stamp) of every message in the bag; raw: the serialized bytes instead."""
        with rosbag.Bag(self.bag) as b:
            if raw:
                return [(t, m[1], s) for t, m, s in b.read_messages(topics=topics, raw=True)]
            return [(t, m, s) for t, m, s in b.read_messages(topics=topics)]
