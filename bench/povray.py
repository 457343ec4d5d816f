#!/usr/bin/env python3
"""octrace against POV-Ray 3.7, one thread each, on the same scenes.

    python3 bench/povray.py [--size WxH] [scene ...]
                            (default: fig5_1 fig5_2 fig5_3 fig5_4 fig5_5 fig5_8
                             chessboard spheres600)

Each octrace scene file is translated into an equivalent POV-Ray scene: the
same camera (POV's `angle` is octrace's default 60-degree viewport), the
same spheres, boxes, triangles and rectangles, point lights whose fall-off is
octrace's B/(d + d0) exactly (POV's fade_power 1 with fade_distance d0 gives
2·d0/(d0 + d), so the light's colour is B/(2·d0)), Phong highlights, mirror
reflection, filtered transparency, RDEPTH + 1 trace levels, no
anti-aliasing. Both programs then render it on one thread, three times, at
its RASTER size or at --size WxH (keep RASTER's 4:3 shape; larger images
time the tracing with less noise from start-up). Two times are reported,
each the best of three: the tracing alone (POV-Ray's own "Trace Time";
host-sim's "tracing" time: building the octree and rendering the pixels,
without the PNG encoder, which runs between rows), and the whole
command (start-up, parsing, tracing, writing the PNG). Prints a Markdown
table.

Superquadrics and B-spline surfaces have no exact POV-Ray counterpart, so
scenes with them are skipped.
"""
import os
import re
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def tokens(text):
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    text = re.sub(r"//[^\n]*", " ", text)
    return text.split()


def to_pov(text):
    t = tokens(text)
    i = 0
    params = {"VIEWPOINT": [0, 0, 10], "ORIGIN": [0, 0, 0], "UPVECTOR": [0, 1, 0], "RASTER": [320, 240],
              "RDEPTH": [3], "BACKGROUND": [0, 0, 0], "GAMMA": [2.2], "ATTENUATION": [1], "SAMPLES": [1]}
    arity = {"VIEWPOINT": 3, "ORIGIN": 3, "UPVECTOR": 3, "RASTER": 2, "VIEWPORT": 2, "RDEPTH": 1, "IMAGEFILE": 1,
             "BACKGROUND": 3, "GAMMA": 1, "ATTENUATION": 1, "SAMPLES": 1}
    shapes = {"SPHERE": 5, "BOX": 7, "TRIANGLE": 10, "RECTANGLE": 13, "LIGHT": 4, "SURFACE": 13}
    lights, objects, surfaces = [], [], {}
    while i < len(t):
        kw = t[i].upper()
        i += 1
        if kw in arity:
            params[kw] = t[i:i + arity[kw]]
            i += arity[kw]
        elif kw in shapes:
            v = [float(x) for x in t[i:i + shapes[kw]]]
            i += shapes[kw]
            if kw == "LIGHT":
                lights.append(v)
            elif kw == "SURFACE":
                surfaces[int(v[0])] = v[1:]
            else:
                objects.append((kw, v))
        else:
            return None  # SUPERQUADRIC, BSPLINE: no exact counterpart
    f = lambda v: f"<{v[0]}, {v[1]}, {-v[2]}>"  # POV is left-handed: flip z
    num = lambda key: [float(x) for x in params[key]]
    d0 = num("ATTENUATION")[0]
    out = [f"global_settings {{ assumed_gamma 1.0 max_trace_level {int(num('RDEPTH')[0]) + 1} ambient_light rgb 1 }}",
           f"background {{ rgb <{', '.join(str(c) for c in num('BACKGROUND'))}> }}",
           f"camera {{ perspective location {f(num('VIEWPOINT'))} look_at {f(num('ORIGIN'))} sky {f(num('UPVECTOR'))} "
           f"right x*{num('RASTER')[0] / num('RASTER')[1]} angle 60 }}"]
    for b, x, y, z in lights:
        out.append(f"light_source {{ {f([x, y, z])} color rgb {b / (2 * d0)} fade_distance {d0} fade_power 1 }}")
    for n, s in surfaces.items():
        amb, dif, spec, k, refl, tr = s[0:3], s[3:6], s[6:9], s[9], s[10], s[11]
        out.append(f"#declare S{n} = texture {{ pigment {{ rgbf <{dif[0]}, {dif[1]}, {dif[2]}, {tr}> }} "
                   f"finish {{ ambient rgb <{amb[0]}, {amb[1]}, {amb[2]}> diffuse 1 "
                   f"phong {sum(spec) / 3} phong_size {max(k, 1)} reflection {refl} }} }}")
    for kw, v in objects:
        s = int(v[0])
        if kw == "SPHERE":
            out.append(f"sphere {{ {f(v[2:5])}, {v[1]} texture {{ S{s} }} }}")
        elif kw == "BOX":
            c, h = v[1:4], v[4:7]
            out.append(f"box {{ {f([c[a] - h[a] for a in range(3)])}, {f([c[a] + h[a] for a in range(3)])} "
                       f"texture {{ S{s} }} }}")
        elif kw == "TRIANGLE":
            out.append(f"triangle {{ {f(v[1:4])}, {f(v[4:7])}, {f(v[7:10])} texture {{ S{s} }} }}")
        else:
            p = [v[1:4], v[4:7], v[7:10], v[10:13]]
            out.append(f"polygon {{ 5, {f(p[0])}, {f(p[1])}, {f(p[2])}, {f(p[3])}, {f(p[0])} texture {{ S{s} }} }}")
    w, h = (int(x) for x in params["RASTER"])
    return "\n".join(out) + "\n", w, h, len(objects), num("GAMMA")[0]


def best_of(runs, command, trace_time):
    """(best wall-clock time, best trace time) of `runs` runs."""
    wall, trace = float("inf"), float("inf")
    for _ in range(runs):
        start = time.perf_counter()
        done = subprocess.run(command, check=True, capture_output=True, text=True)
        wall = min(wall, time.perf_counter() - start)
        trace = min(trace, trace_time(done.stdout + done.stderr))
    return wall, trace


def povray_trace(output):
    return float(re.search(r"Trace Time:.*\(([0-9.]+) seconds\)", output).group(1))


def octrace_trace(output):
    return float(re.search(r"tracing ([0-9.]+) s\)", output).group(1))


def main():
    args = sys.argv[1:]
    size = None
    if args[:1] == ["--size"]:
        size = tuple(int(x) for x in args[1].split("x"))
        args = args[2:]
    names = args or ["fig5_1", "fig5_2", "fig5_3", "fig5_4", "fig5_5", "fig5_8", "chessboard", "spheres600"]
    host_sim = os.path.join(ROOT, "target/release/host-sim")
    subprocess.run(["cargo", "build", "--release", "-q", "-p", "host-sim"], cwd=ROOT, check=True)
    print("| scene | size | objects | POV-Ray 3.7 trace | octrace trace | faster by | POV-Ray command | octrace command | faster by |")
    print("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    with tempfile.TemporaryDirectory() as tmp:
        for name in names:
            path = os.path.join(ROOT, "scenes", name + ".txt")
            translated = to_pov(open(path).read())
            if translated is None:
                print(f"| {name} | skipped: superquadrics or B-splines | | | | | | | |")
                continue
            pov, w, h, count, gamma = translated
            w, h = size or (w, h)
            pov_file = os.path.join(tmp, name + ".pov")
            open(pov_file, "w").write(pov)
            povray = ["povray", f"+I{pov_file}", f"+O{tmp}/{name}-pov.png", f"+W{w}", f"+H{h}", "-D", "-A",
                      "+WT1", f"Display_Gamma={gamma}"]
            octrace = [host_sim, path, f"{tmp}/{name}.png", "--threads", "1", "--size", f"{w}x{h}"]
            (pw, pt), (ow, ot) = best_of(3, povray, povray_trace), best_of(3, octrace, octrace_trace)
            ms = lambda x: f"{x * 1e3:.0f} ms"
            print(f"| {name} | {w}×{h} | {count} | {ms(pt)} | {ms(ot)} | {pt / ot:.2f}× | {ms(pw)} | {ms(ow)} | "
                  f"{pw / ow:.1f}× |")


if __name__ == "__main__":
    main()
