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
    with virtual_display() as display: ...           the same from Python ("DISPLAY" value)"""
import contextlib
import os
import random
import shutil
import subprocess
import sys
import tempfile


@contextlib.contextmanager
def virtual_display(attempts=20):
    xvfb = shutil.which("Xvfb")
    if xvfb is None:
        raise RuntimeError("Xvfb is not installed: apt-get install xvfb")
    failures = []
    for number in random.Random().sample(range(1000, 30000), attempts):
        with tempfile.TemporaryFile() as log:
            read_end, write_end = os.pipe()
            server = subprocess.Popen(
                [xvfb, f":{number}", "-displayfd", str(write_end), "-screen", "0", "1280x1024x24",
                 "-nolisten", "tcp", "-noreset"],
                pass_fds=(write_end,), stdin=subprocess.DEVNULL, stdout=log, stderr=log)
            os.close(write_end)
            with os.fdopen(read_end, "rb") as pipe:
                ready = pipe.readline().strip()  # written once the server accepts connections
            if not ready:  # the number is taken, or Xvfb cannot start at all
                server.wait(timeout=30)
                log.seek(0)
                failures.append(f":{number}: " + log.read().decode(errors="replace").strip())
                continue
            try:
                yield f":{number}"
            finally:
                if server.poll() is not None:
                    log.seek(0)
                    print(f"Xvfb :{number} exited early with code {server.returncode}:\n"
                          + log.read().decode(errors="replace"), file=sys.stderr)
                else:
                    server.terminate()
                    try:
                        server.wait(timeout=10)
                    except subprocess.TimeoutExpired:
                        server.kill()
                        server.wait()
            return
    raise RuntimeError("Xvfb did not start:\n" + "\n".join(failures[-3:]))


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
