"""The client of the client-server test: pvpython connected to a pvserver running
on several ranks, loading the plugin on the server as ParaView does, solving the Cornell box
of pvbatch_parallel.py and fetching the Elements and Patches of frame 0 to the client (the
ranks' pieces appended). Writes them to PREFIX.rank0.npz in pvbatch_parallel.py's format.

    pvpython pvpython_client.py --port P --plugin MovingLightRadiosity.so --out PREFIX"""
import argparse
import os

import numpy as np

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--port", type=int, required=True)
parser.add_argument("--plugin", required=True)
parser.add_argument("--out", required=True)
args = parser.parse_args()

from paraview import servermanager  # noqa: E402
from paraview.simple import Connect, LoadPlugin, XMLPolyDataReader  # noqa: E402
from parallel_support import record_mesh  # noqa: E402

if not Connect("localhost", args.port):
    raise SystemExit(f"could not connect to the pvserver on port {args.port}")
LoadPlugin(args.plugin, remote=True, ns=globals())
if "MovingLightRadiosity" not in globals():
    raise SystemExit("LoadPlugin on the server did not define MovingLightRadiosity")

DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, os.pardir, "Data")
box = XMLPolyDataReader(FileName=[os.path.join(DATA, "cornell_box.vtp")])
light = XMLPolyDataReader(FileName=[os.path.join(DATA, "cornell_light.vtp")])
trajectory = XMLPolyDataReader(FileName=[os.path.join(DATA, "cornell_trajectory.vtp")])
radiosity = MovingLightRadiosity(Scene=box, Light=light, Trajectory=trajectory,  # noqa: F821
                                 PatchSize=0.12, NumberOfPaths=20000, NumberOfThreads=1, Seed=1)
radiosity.UpdatePipeline(time=0.0)
results = {}
for name, port in (("e", 0), ("p", 1)):
    data = servermanager.Fetch(radiosity, idx=port)
    if name == "e":
        results["f0_solves"] = np.array(data.GetFieldData().GetArray("SolveCount").GetValue(0))
        results["f0_ranks"] = np.array(data.GetFieldData().GetArray("Ranks").GetValue(0)
                                       if data.GetFieldData().GetArray("Ranks") else 1)
    record_mesh(results, "f0_" + name, data)
np.savez(f"{args.out}.rank0.npz", **results)
print(f"client: wrote {args.out}.rank0.npz", flush=True)
