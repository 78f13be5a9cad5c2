"""Runs that keep to themselves: two headless scripts/sim runs started at the same moment
each get a ROS master of their own and finish with their own results; --local-only refuses in one line
(exit 4) where no network namespace can be made. Needs the built workspace (the nodes), no master."""
import os
import re
import subprocess
import sys

import pytest

SIM = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts", "sim")
PORT = re.compile(r"^sim: ROS master of its own on port (\d+)", re.M)


def start(tmp, name, *extra):
    log = open(os.path.join(tmp, name + ".log"), "w")
    args = [sys.executable, SIM] + list(extra) + ["headless:=true", "field:=line", "duration:=2",
                                                  "metrics_output:=" + os.path.join(tmp, name + ".yaml")]
    return subprocess.Popen(args, stdout=log, stderr=subprocess.STDOUT), log


def test_two_headless_runs_at_once_keep_apart(tmpdir_path):
    runs = [start(tmpdir_path, n) for n in ("a", "b")]
    ports = []
    for (proc, log), name in zip(runs, ("a", "b")):
        code = proc.wait(timeout=180)
        log.close()
        text = open(os.path.join(tmpdir_path, name + ".log")).read()
        assert code == 0, text[-3000:]
        assert text.rstrip().endswith("sim: the run ended normally"), text[-3000:]
        assert "lockstep scenario finished: 2.000 s simulated" in text, text[-3000:]
        with open(os.path.join(tmpdir_path, name + ".yaml")) as f:
            assert "itae" in f.read()
        ports += PORT.findall(text)
    assert len(ports) == 2 and ports[0] != ports[1], ports


def test_local_only_refused_in_one_line(tmpdir_path):
    # An `unshare` that fails as a kernel without unprivileged user namespaces makes it fail.
    os.symlink("/bin/false", os.path.join(tmpdir_path, "unshare"))
    env = dict(os.environ, PATH=tmpdir_path + os.pathsep + os.environ.get("PATH", ""))
    proc = subprocess.run([sys.executable, SIM, "--local-only", "headless:=true"], env=env, stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, universal_newlines=True, timeout=60)
    assert proc.returncode == 4, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "--local-only" in lines[0] and "not started" in lines[0], proc.stderr


@pytest.mark.skipif(subprocess.run(["unshare", "-rn", "true"], stderr=subprocess.DEVNULL).returncode != 0,
                    reason="no unprivileged network namespace here (unshare -rn)")
def test_local_only_run(tmpdir_path):
    proc, log = start(tmpdir_path, "local", "--local-only")
    code = proc.wait(timeout=180)
    log.close()
    text = open(os.path.join(tmpdir_path, "local.log")).read()
    assert code == 0 and ", local only" in text, text[-3000:]
    assert os.path.isfile(os.path.join(tmpdir_path, "local.yaml"))
