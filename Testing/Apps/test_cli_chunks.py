"""Long animations on the command line: --frames-per-chunk solves the frames in chunks, the
statistics say so, the frames agree with a run in one chunk within the noise, and a run
interrupted in its third chunk leaves no file behind.

ctest sets MLR_CLI (the executable) and MLR_DATA_DIR (Data/); by hand:
    MLR_CLI=build/bin/moving-light-radiosity /usr/bin/python3 -m pytest Testing/Apps/test_cli_chunks.py
"""
import json
import os
import signal
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), os.pardir, "Support"))
from cli_support import CLI, FAST, LIGHT, SCENE, all_files, lines_until, run  # noqa: E402

from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402
from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader  # noqa: E402
import numpy  # noqa: E402

PATH = ["--from", "0.15,0.5478,0.15", "--to", "0.40,0.5478,0.40"]
FRAMES = 12


def mean_radiosity(path):
    reader = vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    return float(numpy.mean(vtk_to_numpy(reader.GetOutput().GetCellData().GetArray("Radiosity"))))


def field_values(path):
    """The first value of each field data array of a .vtu, by name."""
    reader = vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    data = reader.GetOutput().GetFieldData()
    arrays = (data.GetAbstractArray(i) for i in range(data.GetNumberOfArrays()))
    return {a.GetName(): a.GetVariantValue(0).ToDouble() for a in arrays
            if a.GetNumberOfTuples() > 0 and a.GetNumberOfComponents() == 1}


def test_chunks_are_reported_and_agree_with_one_chunk(tmp_path):
    common = ["--scene", SCENE, "--light", LIGHT] + PATH + ["--frames", str(FRAMES),
                                                            "--error-batches", "1"] + FAST
    chunked = run(common + ["--frames-per-chunk", "4", "--output", "c/s.pvd",
                            "--stats", "c/s.json"], tmp_path)
    assert chunked.returncode == 0, chunked.stderr
    assert "chunk 3 of 3: frames 8 to 11" in chunked.stdout
    whole = run(common + ["--output", "w/s.pvd", "--stats", "w/s.json"], tmp_path)
    assert whole.returncode == 0, whole.stderr
    stats = json.loads((tmp_path / "c/s.json").read_text())
    assert stats["settings"]["framesPerChunk"] == 4
    assert stats["statistics"]["Chunks"] == 3 and stats["statistics"]["FramesPerChunk"] == 4
    assert stats["statistics"]["Frames"] == FRAMES
    assert json.loads((tmp_path / "w/s.json").read_text())["statistics"]["Chunks"] == 1
    assert len([f for f in all_files(tmp_path / "c") if f.endswith(".vtu")]) == FRAMES
    # A streamed frame holds its chunk's solve, named, in the run's layout of chunks.
    last = field_values(tmp_path / "c/s_0010.vtu")
    assert last["Chunk"] == 3 and last["Chunks"] == 3 and last["FramesPerChunk"] == 4
    assert last["ChunkOverlap"] == stats["statistics"]["ChunkOverlap"]
    assert last["PathsCast"] < stats["statistics"]["PathsCast"]
    assert "Chunk" not in field_values(tmp_path / "w/s_0010.vtu")
    # A frame's mean radiosity over the box has a relative standard error of about
    # 1/sqrt(N) = 0.7% at N = 20,000; the seams (frames 3, 4, 7, 8) too: 5% is far outside.
    for f in range(FRAMES):
        c = mean_radiosity(tmp_path / f"c/s_{f:04d}.vtu")
        w = mean_radiosity(tmp_path / f"w/s_{f:04d}.vtu")
        assert abs(c - w) < 0.05 * w, (f, c, w)


def test_frames_per_chunk_of_one_is_refused(tmp_path):
    result = run(["--frames-per-chunk", "1"], tmp_path)
    assert result.returncode == 2
    assert "--frames-per-chunk is 1: give 0" in result.stderr
    assert all_files(tmp_path) == []


def test_chunk_overlap_solves_more_positions_and_is_reported(tmp_path):
    common = ["--scene", SCENE, "--light", LIGHT] + PATH + ["--frames", str(FRAMES),
                                                            "--error-batches", "1"] + FAST
    result = run(common + ["--frames-per-chunk", "4", "--chunk-overlap", "2", "--output",
                           "c/s.pvd", "--stats", "c/s.json"], tmp_path)
    assert result.returncode == 0, result.stderr
    # m = 2 positions on each side, where the default C/8 gives 1.
    assert "chunk 2 of 3: frames 4 to 7, solving positions 2 to 9" in result.stdout
    stats = json.loads((tmp_path / "c/s.json").read_text())
    assert stats["settings"]["chunkOverlap"] == 2
    assert stats["statistics"]["ChunkOverlap"] == 2
    default = run(common + ["--frames-per-chunk", "4", "--output", "d/s.pvd", "--stats",
                            "d/s.json"], tmp_path)
    assert default.returncode == 0, default.stderr
    assert "chunk 2 of 3: frames 4 to 7, solving positions 3 to 8" in default.stdout
    assert json.loads((tmp_path / "d/s.json").read_text())["statistics"]["ChunkOverlap"] == 1


def test_chunk_overlap_over_half_a_chunk_is_refused(tmp_path):
    result = run(["--frames-per-chunk", "4", "--chunk-overlap", "3"], tmp_path)
    assert result.returncode == 2
    assert "--chunk-overlap is 3, more than half of --frames-per-chunk (4): give 0 (an " \
        "eighth of a chunk) or at most 2" in result.stderr
    assert all_files(tmp_path) == []
    negative = run(["--chunk-overlap", "-1"], tmp_path)
    assert negative.returncode == 2
    assert "--chunk-overlap is -1: give a value from 0 to" in negative.stderr, negative.stderr
    assert all_files(tmp_path) == []


def test_interrupt_in_the_third_chunk_writes_nothing(tmp_path):
    process = subprocess.Popen(
        [CLI, "--scene", SCENE, "--light", LIGHT] + PATH +
        ["--frames", "16", "--frames-per-chunk", "4", "--paths", "3000000", "--patch-size",
         "0.08", "--error-batches", "1", "--output", "out/s.pvd", "--stats", "out/s.json"],
        cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        seen = lines_until(process, "chunk 3 of 4", 240)
        assert any("chunk 3 of 4" in line for line in seen), (seen, process.poll())
        assert process.poll() is None, "the run ended before it was interrupted"
        process.send_signal(signal.SIGINT)
        stdout, stderr = process.communicate(timeout=60)
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
    assert process.returncode == 1, stderr
    assert "interrupted: nothing was written" in stderr
    assert all_files(tmp_path) == []


def test_streamed_chunks_print_the_error_line_and_time_their_writing(tmp_path):
    """A run in chunks streams its frames to the writers during the solve: its summary has the
    error line of a run in one chunk, from every frame's figures, and --stats counts the
    frames converted and handed to the writers then as writing, not solving."""
    common = ["--scene", SCENE, "--light", LIGHT] + PATH + ["--frames", str(FRAMES), "--paths",
                                                            "20000", "--patch-size", "0.04"]
    chunked = run(common + ["--frames-per-chunk", "4", "--output", "c/s.pvd",
                            "--stats", "c/s.json"], tmp_path)
    assert chunked.returncode == 0, chunked.stderr
    whole = run(common + ["--output", "w/s.pvd", "--stats", "w/s.json"], tmp_path)
    assert whole.returncode == 0, whole.stderr
    stats = json.loads((tmp_path / "c/s.json").read_text())
    whole_stats = json.loads((tmp_path / "w/s.json").read_text())
    assert stats["statistics"]["Chunks"] == 3

    lines = [line for line in chunked.stdout.splitlines()
             if line.startswith("relative error of the lit elements: median ")]
    assert len(lines) == 1, chunked.stdout
    p95 = stats["errorEstimate"]["RelativeErrorP95"]
    assert len(p95) == FRAMES and len(stats["errorEstimate"]["RelativeErrorMedian"]) == FRAMES
    assert all(value > 0 for value in p95)
    worst = max(range(FRAMES), key=lambda f: p95[f])
    assert f"(frame {worst}, the worst)" in lines[0]
    # Each frame's figures come from its chunk's 16 batches, as in one chunk (it said 48).
    assert ", 16 batches in 1 round, stopped by batches" in lines[0], lines[0]
    assert stats["statistics"]["ErrorBatches"] == whole_stats["statistics"]["ErrorBatches"] == 16
    # The same paths per frame as the run in one chunk: the same error within the noise.
    whole_p95 = whole_stats["errorEstimate"]["RelativeErrorP95"]
    assert 0.5 < max(p95) / max(whole_p95) < 2

    timing = stats["timing"]
    streaming = stats["statistics"]["SecondsStreaming"]
    assert 0 < streaming <= timing["secondsWriting"]
    assert "SecondsStreaming" not in whole_stats["statistics"]
    stages = ("secondsReading", "secondsRemeshing", "secondsSolving", "secondsWriting")
    assert sum(timing[key] for key in stages) <= timing["secondsTotal"] + 1e-6


def test_chunks_of_two_frames_stream_every_frame(tmp_path):
    """With chunks of 2 the first chunk hands on its frame 0 alone, before its seam: a
    streamed frame, not a solve of one frame."""
    result = run(["--scene", SCENE, "--light", LIGHT] + PATH +
                 ["--frames", "5", "--frames-per-chunk", "2", "--error-batches", "1",
                  "--output", "out/s.pvd"] + FAST, tmp_path)
    assert result.returncode == 0, result.stderr
    assert "chunk 3 of 3: frames 4 to 4" in result.stdout
    assert all_files(tmp_path / "out") == ["s.pvd"] + [f"s_{f:04d}.vtu" for f in range(5)]


def test_a_memory_refusal_in_chunks_counts_a_chunks_positions(tmp_path):
    # Streamed in chunks, a chunk's positions are what the solve holds, its overlap included;
    # the advice is about the chunks' length, and when the limit already chose the shortest
    # chunks it does not ask for fewer frames.
    common = ["--scene", SCENE, "--light", LIGHT] + PATH + ["--frames", "300",
                                                            "--patch-size", "0.005",
                                                            "--memory-limit", "300",
                                                            "--output", "s.pvd"]
    given = run(common + ["--frames-per-chunk", "40"], tmp_path)
    assert given.returncode == 1, given.stderr
    assert "(50 positions (a chunk of 40 frames and 5 more on each side) x (about" \
        in given.stderr, given.stderr
    assert "use fewer frames per chunk (FramesPerChunk, --frames-per-chunk; 0 lets the " \
        "memory limit choose)" in given.stderr, given.stderr
    chosen = run(common, tmp_path)
    assert chosen.returncode == 1, chosen.stderr
    assert "(4 positions (a chunk of 2 frames and 1 more on each side) x (about" \
        in chosen.stderr, chosen.stderr
    assert "even chunks of 2 frames do not fit: use a larger patch size" in chosen.stderr
    assert "fewer frames" not in chosen.stderr, chosen.stderr
    assert all_files(tmp_path) == []
