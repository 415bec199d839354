"""A private virtual X display for the rendering tests and the examples (Debian's ParaView
renders through GLX only, so pvbatch screenshots and the paraview GUI need an X server). It is
the project's one way to get a display off-screen: Examples/example_support.py uses this module
when DISPLAY is unset, and the command line does the same in C++ for --png (PictureDisplay in
Apps/FrameRenderer.cxx).

Two ways an X display fails ParaView with "bad X server connection" (SIGABRT):
- ParaView opens a first X connection and closes it before the render window opens its own.
  Xvfb resets when its last client leaves, and a connection arriving during the reset is
  dropped; on a busy machine (tests in parallel) that happens often. -noreset prevents it,
  which plain xvfb-run does not pass.
- xvfb-run -a takes the first display number without a lock file, so two runs starting
  together can take the same one. Here each display gets a random number among thousands, the
  X server refuses one in use (its lock file), and -displayfd tells when it accepts clients.

    python3 xvfb_display.py COMMAND [ARGUMENTS...]   runs COMMAND with DISPLAY set, returns
                                                     its exit code
    with virtual_display() as display: ...           the same from Python ("DISPLAY" value)
    display_for_this_process()                       one that ends with the process"""
import contextlib
import ctypes
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile


def _start(attempts, preexec_fn=None):
    """An Xvfb server on a free display: (the process, ":N")."""
    xvfb = shutil.which("Xvfb")
    if xvfb is None:
        raise RuntimeError("Xvfb is not installed: apt-get install xvfb")
    failures = []
    for number in random.Random().sample(range(1000, 30000), attempts):
        log = tempfile.TemporaryFile()
        read_end, write_end = os.pipe()
        server = subprocess.Popen(
            [xvfb, f":{number}", "-displayfd", str(write_end), "-screen", "0", "1280x1024x24",
             "-nolisten", "tcp", "-noreset"],
            pass_fds=(write_end,), stdin=subprocess.DEVNULL, stdout=log, stderr=log,
            preexec_fn=preexec_fn)
        os.close(write_end)
        with os.fdopen(read_end, "rb") as pipe:
            ready = pipe.readline().strip()  # written once the server accepts connections
        if ready:
            server.log = log
            return server, f":{number}"
        server.wait(timeout=30)  # the number is taken, or Xvfb cannot start at all
        log.seek(0)
        failures.append(f":{number}: " + log.read().decode(errors="replace").strip())
        log.close()
    raise RuntimeError("Xvfb did not start:\n" + "\n".join(failures[-3:]))


@contextlib.contextmanager
def virtual_display(attempts=20):
    server, display = _start(attempts)
    try:
        yield display
    finally:
        if server.poll() is not None:
            server.log.seek(0)
            print(f"Xvfb {display} exited early with code {server.returncode}:\n"
                  + server.log.read().decode(errors="replace"), file=sys.stderr)
        else:
            server.terminate()
            try:
                server.wait(timeout=10)
            except subprocess.TimeoutExpired:
                server.kill()
                server.wait()
        server.log.close()


def display_for_this_process(attempts=20):
    """A private display that lives as long as this process: the kernel stops its Xvfb when
    the process ends, however it ends (PR_SET_PDEATHSIG). For scripts run by pvbatch, whose
    ParaView closes its X connection after Python's exit handlers have run: a server stopped
    by such a handler made that close fail (an X I/O error, then a double free whose abort
    handler hangs pvbatch for ever). Call it from the main thread: the kernel stops the server
    when the thread that started it ends."""
    parent = os.getpid()
    libc = ctypes.CDLL(None, use_errno=True)

    def die_with_parent():
        libc.prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG
        if os.getppid() != parent:  # the parent ended before the call took effect
            os._exit(1)

    return _start(attempts, die_with_parent)[1]


def main(command):
    if not command:
        sys.exit("usage: python3 xvfb_display.py COMMAND [ARGUMENTS...]")
    with virtual_display() as display:
        code = subprocess.call(command, env=dict(os.environ, DISPLAY=display))
    if code < 0:
        print(f"{command[0]} was killed by signal {-code}", file=sys.stderr)
        return 1
    return code


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
