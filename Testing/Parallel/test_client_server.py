#!/usr/bin/python3
"""Client-server test: starts `mpiexec -n 2 pvserver` on a free loopback port,
connects pvpython_client.py to it, and checks that the Elements and Patches the client
fetches are the serial pvbatch result, array by array, bit for bit (cells matched by their
corners). Every process is bounded by a timeout, and the server's process group is killed at
the end, so nothing is left behind.

    test_client_server.py --mpiexec M --pvserver S --pvpython C --pvbatch B --plugin P --work DIR"""
import argparse
import os
import signal
import socket
import subprocess
import sys
import time

import numpy as np

import run_parallel

HERE = os.path.dirname(os.path.abspath(__file__))


def free_port():
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    for name in ("mpiexec", "pvserver", "pvpython", "pvbatch", "plugin", "work"):
        parser.add_argument("--" + name, required=True)
    args = parser.parse_args()
    os.makedirs(args.work, exist_ok=True)
    checks = run_parallel.Checks()
    serial = os.path.join(args.work, "serial")
    run_parallel.run([args.pvbatch, "--force-offscreen-rendering", run_parallel.SCRIPT, "--plugin",
                      args.plugin, "--case", "whole", "--out", serial], "serial pvbatch")
    reference = run_parallel.load(serial)[0]

    port = free_port()
    log_path = os.path.join(args.work, "pvserver.log")
    with open(log_path, "w") as log:
        server = subprocess.Popen(
            [args.mpiexec, "--allow-run-as-root", "--oversubscribe", "-n", "2", args.pvserver,
             "--force-offscreen-rendering", f"--server-port={port}"],
            stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
    try:
        deadline = time.time() + 60
        while "Accepting connection" not in open(log_path).read():
            if server.poll() is not None or time.time() > deadline:
                sys.exit(f"pvserver did not start listening on port {port}:\n{open(log_path).read()[-3000:]}")
            time.sleep(0.2)
        client = os.path.join(args.work, "client")
        run_parallel.run([args.pvpython, "--force-offscreen-rendering",
                          os.path.join(HERE, "pvpython_client.py"), "--port", str(port),
                          "--plugin", args.plugin, "--out", client], "pvpython client")
    finally:
        try:
            os.killpg(server.pid, signal.SIGTERM)
            server.wait(timeout=20)
        except (ProcessLookupError, subprocess.TimeoutExpired):
            try:
                os.killpg(server.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            server.wait()
    fetched = run_parallel.load(client)[0]
    checks.check(int(fetched["f0_ranks"]) == 2, f"the server solved on {int(fetched['f0_ranks'])} ranks, not 2")
    checks.check(int(fetched["f0_solves"]) == 1, f"SolveCount {int(fetched['f0_solves'])}")
    for kind in ("e", "p"):
        run_parallel.compare(checks, reference, [fetched], "f0_", kind, ordered=False)
    checks.finish("Parallel.ClientServer")


if __name__ == "__main__":
    main()
