"""A single-node Slurm cluster on localhost from a temporary directory (the test suite's; also a
way to try `doe run --backend slurm` on one machine): its own munge key and socket, a generated
slurm.conf with its own ports, slurmctld and slurmd in the foreground under this process, and the
job completion log (jobcomp/filetxt) that `sacct -c` reads. Debian 12's slurmctld, slurmd,
slurm-client and munge (scripts/lib.sh DM_SLURM_PACKAGES).

    with LocalCluster() as c:          # c.env: SLURM_CONF for sbatch, squeue, sacct, scancel
        subprocess.run(['sbatch', ...], env=c.env)

    python3 -m dem_mobility_tools.doe.local_cluster DIR     (starts one and waits for Ctrl-C)
"""
import os
import shutil
import signal
import socket
import subprocess
import tempfile
import time

from ..runs import free_port


class ClusterError(RuntimeError):
    pass


def tool(name):
    """The path of a Slurm or munge program (the daemons are in /usr/sbin, often not on PATH)."""
    path = shutil.which(name) or shutil.which(name, path='/usr/sbin:/usr/bin:/sbin:/bin')
    if path is None:
        raise ClusterError('%s not found: install %s (scripts/lib.sh DM_SLURM_PACKAGES)' % (
            name, 'munge' if 'munge' in name else 'slurmctld slurmd slurm-client'))
    return path


class LocalCluster:
    def __init__(self, root=None, cpus=None, timeout=30.0):
        self.own_root = root is None
        self.root = root or tempfile.mkdtemp(prefix='dm_slurm_')
        self.cpus = cpus or os.cpu_count() or 1
        self.timeout = timeout
        self.procs = []
        self.env = None
        self.host = socket.gethostname().split('.')[0]

    # -- files
    def _write_conf(self):
        r = self.root
        for d in ('munge', 'log', 'state', 'spool', 'out'):
            os.makedirs(os.path.join(r, d), exist_ok=True)
        os.chmod(r, 0o755)
        os.chmod(os.path.join(r, 'munge'), 0o755)  # munged: the socket's folder must be o+x, and its parents
        d = os.path.dirname(os.path.abspath(r))
        while d != os.path.dirname(d):
            if not os.stat(d).st_mode & 0o001:
                raise ClusterError('%s: munged needs every folder above its socket executable for all (chmod o+x %s)'
                                   % (r, d))
            d = os.path.dirname(d)
        p1, p2 = free_port(), free_port()
        while p2 == p1:
            p2 = free_port()
        conf = {
            'ClusterName': 'dmtest', 'SlurmctldHost': '%s(127.0.0.1)' % self.host,
            'SlurmctldPort': p1, 'SlurmdPort': p2, 'SlurmUser': 'root', 'SlurmdUser': 'root',
            'AuthType': 'auth/munge', 'CredType': 'cred/munge', 'AuthInfo': 'socket=%s/munge/munge.socket' % r,
            'StateSaveLocation': r + '/state', 'SlurmdSpoolDir': r + '/spool/%n',
            'SlurmctldPidFile': r + '/slurmctld.pid', 'SlurmdPidFile': r + '/slurmd.pid',
            'SlurmctldLogFile': r + '/log/slurmctld.log', 'SlurmdLogFile': r + '/log/slurmd.log',
            'ProctrackType': 'proctrack/linuxproc', 'TaskPlugin': 'task/none',
            'JobAcctGatherType': 'jobacct_gather/none', 'AccountingStorageType': 'accounting_storage/none',
            'JobCompType': 'jobcomp/filetxt', 'JobCompLoc': r + '/jobcomp.txt',
            'SelectType': 'select/cons_tres', 'SelectTypeParameters': 'CR_CPU', 'SchedulerType': 'sched/builtin',
            'MpiDefault': 'none', 'ReturnToService': 2, 'MinJobAge': 3600, 'MailProg': '/bin/true',
        }
        lines = ['%s=%s' % kv for kv in conf.items()]
        lines.append('NodeName=%s NodeAddr=127.0.0.1 CPUs=%d RealMemory=1000 State=UNKNOWN' % (self.host, self.cpus))
        lines.append('PartitionName=dm Nodes=%s Default=YES MaxTime=INFINITE State=UP' % self.host)
        path = os.path.join(r, 'slurm.conf')
        with open(path, 'w') as fh:
            fh.write('# a single-node test cluster (dm_doe.local_cluster)\n' + '\n'.join(lines) + '\n')
        return path

    # -- start and stop
    def start(self):
        for exe in ('munged', 'mungekey', 'slurmctld', 'slurmd', 'sbatch', 'sinfo', 'scontrol'):
            tool(exe)
        conf = self._write_conf()
        m = os.path.join(self.root, 'munge')
        key = os.path.join(m, 'munge.key')
        self._run([tool('mungekey'), '-c', '-k', key, '-b', '1024'])
        os.chmod(key, 0o600)
        self._run([tool('munged'), '--key-file=' + key, '--socket=%s/munge.socket' % m, '--pid-file=%s/munged.pid' % m,
                   '--log-file=%s/log/munged.log' % self.root, '--seed-file=%s/munged.seed' % m])
        self.env = dict(os.environ, SLURM_CONF=conf)
        for argv in ([tool('slurmctld'), '-D', '-c', '-i', '-f', conf], [tool('slurmd'), '-D', '-f', conf, '-N', self.host]):
            log = open(os.path.join(self.root, 'log', os.path.basename(argv[0]) + '.console'), 'w')
            self.procs.append(subprocess.Popen(argv, stdout=log, stderr=subprocess.STDOUT, env=self.env,
                                               start_new_session=True))
            log.close()
        t0 = time.time()
        while time.time() - t0 < self.timeout:
            for p in self.procs:
                if p.poll() is not None:
                    err = ClusterError('%s exited (%d) at start; see %s/log' % (p.args[0], p.returncode, self.root))
                    self.own_root = False  # keep the logs
                    self.stop()
                    raise err
            q = subprocess.run(['sinfo', '-h', '-N', '-o', '%T'], capture_output=True, text=True, env=self.env)
            if q.returncode == 0 and q.stdout.strip() in ('idle', 'mixed', 'allocated'):
                return self
            time.sleep(0.3)
        self.own_root = False  # keep the logs
        self.stop()
        raise ClusterError('the node was not idle after %.0f s; see %s/log' % (self.timeout, self.root))

    def _run(self, argv):
        p = subprocess.run(argv, capture_output=True, text=True)
        if p.returncode != 0:
            raise ClusterError('%s failed (%d): %s' % (' '.join(argv), p.returncode, p.stderr.strip()))

    def stop(self):
        """Cancels the jobs, stops slurmctld and slurmd (scontrol shutdown, then by pid) and munged."""
        if self.env is not None:
            subprocess.run(['scancel', '--user', str(os.getuid())], capture_output=True, env=self.env)
            subprocess.run(['scontrol', 'shutdown'], capture_output=True, env=self.env, timeout=30)
        for p in self.procs:
            try:
                p.wait(10)
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)
                p.wait()
        self.procs = []
        m = os.path.join(self.root, 'munge')
        if os.path.exists(os.path.join(m, 'munge.socket')):
            subprocess.run([tool('munged'), '-s', '--socket=%s/munge.socket' % m], capture_output=True)
        if self.own_root:
            shutil.rmtree(self.root, ignore_errors=True)

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.stop()


def main(argv=None):
    """python3 -m dem_mobility_tools.doe.local_cluster [FOLDER]: a single-node Slurm cluster in
    FOLDER (default: a temporary one) until Ctrl-C."""
    import argparse
    p = argparse.ArgumentParser(prog='python3 -m dem_mobility_tools.doe.local_cluster',
                                description='A single-node Slurm test cluster (slurmctld, slurmd, munged) '
                                            'on this machine until Ctrl-C.')
    p.add_argument('folder', nargs='?', help='its state and configuration (default: a temporary folder)')
    a = p.parse_args(argv)
    c = LocalCluster(a.folder).start()
    print('cluster up: export SLURM_CONF=%s' % c.env['SLURM_CONF'], flush=True)
    try:
        signal.pause()
    except KeyboardInterrupt:
        pass
    finally:
        c.stop()


if __name__ == '__main__':
    main()
