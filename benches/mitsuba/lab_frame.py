#!/usr/bin/env python3
"""The lab frame against Mitsuba 3: the same box, camera and light, direct lighting with N
points on the light per pixel, one thread or two, whole frames timed in alternating blocks.

    python3 -m venv /tmp/mitsuba-venv && /tmp/mitsuba-venv/bin/pip install mitsuba==3.9.1
    cargo build --release
    /tmp/mitsuba-venv/bin/python benches/mitsuba/lab_frame.py target/release/raywave

raywave: `raywave bench scenes/cornell_box_reflective_spheres.obj --bounces 0 --shadows soft
--shadow-samples N --threads T --engine wavefront`, the median of its timed frames (render
only). Mitsuba: `mi.render` of the `direct` integrator (emitter_samples = N, bsdf_samples = 0,
one sample per pixel) in the `llvm_ad_rgb` variant with `dr.set_thread_count(T)`, after a
warm-up render that compiles its kernels, the median of its timed renders (render only).

Differences: the lab's light is the box's front wall, one-sided, which the camera looks
through; Mitsuba's shapes are two-sided, so its near clipping plane is put just past that wall
(`near_clip` 7.01: the wall lies 7.0 in front of the camera), which leaves out the first 0.01
of the walls behind it. raywave shades each wall with its lab material (diffuse and a Phong
highlight), Mitsuba with a plain diffuse BSDF of the same colour, and the spheres as diffuse
(raywave at zero bounces shades them without their mirror rays). Rays that leave the box meet
nothing in either. The images differ in brightness (the lab's light model is not Mitsuba's):
only the work is compared.
"""

import re
import statistics
import subprocess
import sys
import time

import drjit as dr
import mitsuba as mi

SCENE = "scenes/cornell_box_reflective_spheres.obj"
SIZE = 512
SAMPLES = (16, 64)
THREADS = (1, 2)
BLOCKS = 2  # alternating blocks of each renderer
RUNS = 5  # timed frames per block

# The lab box (the scene file's): walls of the [-1, 1]³ cube, the light on z = +1 facing −z.
WALLS = {
    # name: (colour, rectangle's to_world)
    "back": ((0.84, 0.84, 0.84), lambda T: T.translate([0, 0, -1])),
    "ceiling": ((0.84, 0.84, 0.84), lambda T: T.translate([0, 1, 0]).rotate([1, 0, 0], 90)),
    "floor": ((0.54, 0.54, 0.54), lambda T: T.translate([0, -1, 0]).rotate([1, 0, 0], -90)),
    "left": ((1.0, 0.0, 0.0), lambda T: T.translate([-1, 0, 0]).rotate([0, 1, 0], 90)),
    "right": ((0.0, 0.0, 1.0), lambda T: T.translate([1, 0, 0]).rotate([0, 1, 0], -90)),
}
SPHERES = [(-0.5, -0.7, 0.5), (0.0, -0.7, 0.0), (0.5, -0.7, -0.5)]


def scene(n):
    T = mi.ScalarTransform4f
    d = {
        "type": "scene",
        "integrator": {"type": "direct", "emitter_samples": n, "bsdf_samples": 0},
        "sensor": {
            "type": "perspective",
            "fov": 20.0,
            "fov_axis": "y",
            "near_clip": 7.01,
            "far_clip": 100.0,
            "to_world": T.look_at(origin=[0, 0, 8], target=[0, 0, 0], up=[0, 1, 0]),
            "film": {
                "type": "hdrfilm",
                "width": SIZE,
                "height": SIZE,
                "rfilter": {"type": "box"},
            },
            "sampler": {"type": "independent", "sample_count": 1},
        },
        "light": {
            "type": "rectangle",
            "to_world": T.translate([0, 0, 1]).rotate([0, 1, 0], 180),
            "emitter": {"type": "area", "radiance": {"type": "rgb", "value": 1.27}},
        },
    }
    for name, (colour, place) in WALLS.items():
        d[name] = {
            "type": "rectangle",
            "to_world": place(T),
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": colour}},
        }
    for k, c in enumerate(SPHERES):
        d[f"sphere{k}"] = {
            "type": "sphere",
            "center": list(c),
            "radius": 0.3,
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": 0.2}},
        }
    return mi.load_dict(d)


def mitsuba_frames(s, runs):
    out = []
    for _ in range(runs):
        start = time.perf_counter()
        image = mi.render(s, spp=1)
        dr.eval(image)
        dr.sync_thread()
        out.append(time.perf_counter() - start)
    return out


def raywave_frames(binary, n, threads, runs):
    cmd = [binary, "bench", SCENE, "--size", str(SIZE), str(SIZE), "--bounces", "0",
           "--shadows", "soft", "--shadow-samples", str(n), "--threads", str(threads),
           "--engine", "wavefront", "--runs", str(runs)]
    text = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    # "wavefront  total   RAYS   SECONDS   MRAYS  (Mrays/s, wall clock)": the median frame.
    m = re.search(r"^wavefront\s+total\s+\d+\s+([0-9.]+)\s", text, re.M)
    if not m:
        sys.exit(f"lab_frame.py: no wavefront total in the output of {' '.join(cmd)}:\n{text}")
    return float(m.group(1))


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: lab_frame.py PATH/TO/raywave")
    binary = sys.argv[1]
    mi.set_variant("llvm_ad_rgb")
    print(f"Mitsuba {mi.__version__} (llvm_ad_rgb), {SIZE}×{SIZE}, {BLOCKS} alternating blocks "
          f"of {RUNS} frames each, medians\n")
    print("| N | threads | raywave, s | Mitsuba 3, s | Mitsuba / raywave |")
    print("|---:|---:|---:|---:|---:|")
    for threads in THREADS:
        dr.set_thread_count(threads)
        for n in SAMPLES:
            s = scene(n)
            mitsuba_frames(s, 1)  # compiles the kernels
            ours, theirs = [], []
            for _ in range(BLOCKS):
                theirs += mitsuba_frames(s, RUNS)
                ours.append(raywave_frames(binary, n, threads, RUNS))
            a, b = statistics.median(ours), statistics.median(theirs)
            print(f"| {n} | {threads} | {a:.4f} | {b:.4f} | {b / a:.2f}× |", flush=True)


if __name__ == "__main__":
    main()
