"""Runs a command under a virtual X display of its own, for the ParaView screenshot tests.

    python3 with_xvfb.py COMMAND [ARGS...]

`xvfb-run -a` picks its display number by looking for a free lock file and then starting Xvfb, so two
of them starting at the same moment can pick the same number: one Xvfb fails and its command gets "bad
X server connection, DISPLAY=:99" (CI saw it once). Here Xvfb picks the number itself (`-displayfd`:
it takes the first free display atomically and writes the number once it accepts connections), with
retries, and the command runs with DISPLAY set to that server; the server is ended afterwards (by its
own pid).

Exit codes: the command's own; 77 (ctest: skipped) when no virtual display can be had — Xvfb is not
installed, never becomes ready, or dies under the command and the command then fails on the X
connection. A command that fails while its display is alive (ParaView rendering wrongly, a check
failing) fails the test as usual.
"""
import os
import select
import shutil
import subprocess
import sys
import time

SKIP = 77
READY_SECONDS = 20.0
ATTEMPTS = 3


def start_xvfb():
    """(process, display number) of a ready Xvfb, or (None, reason)."""
    xvfb = shutil.which("Xvfb")
    if xvfb is None:
        return None, "Xvfb is not installed (Debian xvfb)"
    reason = ""
    for attempt in range(ATTEMPTS):
        read_end, write_end = os.pipe()
        proc = subprocess.Popen([xvfb, "-displayfd", str(write_end), "-screen", "0", "1024x768x24", "-nolisten", "tcp",
                                 "-noreset"], pass_fds=(write_end,), stdout=subprocess.DEVNULL,
                                stderr=subprocess.PIPE)
        os.close(write_end)
        text = b""
        deadline = time.monotonic() + READY_SECONDS
        while not text.endswith(b"\n") and time.monotonic() < deadline:
            ready, _, _ = select.select([read_end], [], [], 0.2)
            if ready:
                chunk = os.read(read_end, 64)
                if not chunk:  # Xvfb closed the pipe without a number: it exited
                    break
                text += chunk
        os.close(read_end)
        if text.strip().isdigit() and proc.poll() is None:
            return proc, int(text.strip())
        proc.kill()
        _, err = proc.communicate()
        reason = f"Xvfb attempt {attempt + 1} did not become ready: {err.decode(errors='replace').strip()[-300:]}"
        print(f"with_xvfb.py: {reason}", flush=True)
    return None, reason


def main():
    if len(sys.argv) < 2:
        print(__doc__)
        return 2
    proc, display = start_xvfb()
    if proc is None:
        print(f"with_xvfb.py: no virtual display ({display}): skipped", flush=True)
        return SKIP
    print(f"with_xvfb.py: Xvfb pid {proc.pid} on DISPLAY=:{display}", flush=True)
    env = dict(os.environ, DISPLAY=f":{display}")
    try:
        child = subprocess.run(sys.argv[1:], env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
        sys.stdout.write(child.stdout.decode(errors="replace"))
        sys.stdout.flush()
        if child.returncode != 0 and proc.poll() is not None and b"X server" in child.stdout:
            print(f"with_xvfb.py: the X server ended under the command (exit {proc.returncode}): skipped",
                  flush=True)
            return SKIP
        return child.returncode
    finally:
        if proc.poll() is None:
            proc.terminate()
            try:
                proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()


if __name__ == "__main__":
    sys.exit(main())
