"""Measurements of running processes, off /proc and the node's own XML-RPC API: for the bench, the soak and the
tests."""
import os
import platform
import time
import xmlrpc.client


def machine():
    model = 'unknown CPU'
    with open('/proc/cpuinfo') as cpuinfo:
        for line in cpuinfo:
            if line.startswith('model name'):
                model = line.split(':', 1)[1].strip()
                break
    return '%s, %d cores, %s, Python %s' % (model, os.cpu_count(), platform.platform(terse=True),
                                            platform.python_version())


def node_uri(name):
    """XML-RPC URI of the node `name`, or None while the master does not know it."""
    import rosgraph
    try:
        return rosgraph.Master('/tb3_harness').lookupNode(name)
    except rosgraph.MasterException:
        return None


def sim_uri():
    """XML-RPC URI of the /tb3_sim node, or None while it is not registered."""
    return node_uri('/tb3_sim')


def sim_pid():
    """PID of the /tb3_sim node."""
    return node_pid('/tb3_sim')


def cpu_seconds(pid):
    """User + system CPU time (s) of a process and its threads."""
    with open('/proc/%d/stat' % pid) as stat:
        fields = stat.read().rsplit(')', 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')


def node_pid(name):
    """PID of the node `name`, from its own XML-RPC API (as `rosnode info` finds it); None while the
    master does not know it or the node it knows does not answer (one of that name that ended)."""
    uri = node_uri(name)
    if uri is None:
        return None
    try:
        return xmlrpc.client.ServerProxy(uri).getPid('/tb3_harness')[2]
    except OSError:
        return None


class CpuMeter(object):
    """CPU time of named processes from its creation on: the nodes of a run and the master, which
    also works for them (each parameter a node reads at run time is an XML-RPC call to it)."""

    def __init__(self, pids):
        """`pids`: (label, pid) pairs in the order the rows are to be printed; a pid None (a node
        not running) is left out."""
        self.pids = dict((label, pid) for label, pid in pids if pid is not None)
        self._start = dict((label, cpu_seconds(pid)) for label, pid in self.pids.items())
        self._wall = time.monotonic()

    def shares(self):
        """{label: share of a core} since the meter was made (nan for a process that ended)."""
        wall = time.monotonic() - self._wall
        used = {}
        for label, pid in self.pids.items():
            try:
                used[label] = (cpu_seconds(pid) - self._start[label]) / wall
            except OSError:
                used[label] = float('nan')
        return used


def memory_mib(pid, field='VmHWM'):
    """A memory figure of /proc/PID/status in MiB: VmHWM (peak RSS) or VmRSS (now)."""
    with open('/proc/%d/status' % pid) as status:
        for line in status:
            if line.startswith(field + ':'):
                return int(line.split()[1]) / 1024.0
    return float('nan')
