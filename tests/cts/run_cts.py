#!/usr/bin/env python3
"""CTS parity of the layer on the mock runtime (ctest label cts).

Runs the non-interactive cases of the Khronos OpenXR CTS (built by build_cts.sh) for one graphics
configuration and one hand-tracking mode of the mock runtime, first on the runtime alone, then
with the layer installed as an implicit layer: idle (no extension of its own enabled), with
-E XR_EXT_hand_tracking and with -E XR_SDFG_auto_grasp. Each case runs in its own process under a
timeout, so a crash is attributed to one case. Parity: every case that passes on the runtime alone
passes with the layer, and every assertion (file:line) that only ever passed on the runtime alone
never fails with the layer. Prints a table of passed / failed / skipped / crashed per run and
every regression; exit 0 on parity, 1 on a regression, 77 (ctest: skipped) without a CTS build.
"""
import argparse
import os
import shutil
import subprocess
import sys
import time
import xml.etree.ElementTree as ET

SKIP = 77


def parse_args():
    p = argparse.ArgumentParser()
    p.add_argument("--stamp", required=True, help="built.stamp written by build_cts.sh")
    p.add_argument("--mock-json", required=True)
    p.add_argument("--layer-json", required=True)
    p.add_argument("--layer-disable-env", required=True)
    p.add_argument("--work", required=True)
    p.add_argument("--graphics", choices=["vulkan", "vulkan2", "headless"], required=True)
    p.add_argument("--hand-tracking", choices=["1", "0", "absent"], required=True)
    p.add_argument("--case-timeout", type=float, default=120.0)
    p.add_argument("--cases", default="", help="comma-separated case names (default: all)")
    return p.parse_args()


def cts_args(graphics):
    # The mock runtime is OpenXR 1.0; headless sessions use XR_MND_headless and no plugin.
    args = ["--apiVersion", "1.0"]
    if graphics == "headless":
        args += ["-E", "XR_MND_headless"]
    else:
        args += ["-G", graphics]
    return args


def escape(name):
    # Catch2 test specs: ',' separates, '[' starts a tag, '\\' escapes.
    out = name
    for ch in "\\,[]":
        out = out.replace(ch, "\\" + ch)
    return out


def list_cases(cli, cwd, env):
    r = subprocess.run([cli, "exclude:[interactive]", "--list-tests", "--verbosity", "quiet"],
                       cwd=cwd, env=env, capture_output=True, text=True, timeout=120)
    # A banner, then "Test names:" and one name per line (the list may repeat).
    names = []
    listing = False
    for line in r.stdout.splitlines():
        line = line.strip()
        if line == "Test names:":
            listing = True
        elif listing and line and " " not in line and line[0] not in "*<":
            if line not in names:
                names.append(line)
    return names


def run_case(cli, cwd, env, name, extra, out_xml, timeout):
    """Returns (status, {key: [passes, failures]}) with status passed/failed/skipped/crashed."""
    if os.path.exists(out_xml):
        os.remove(out_xml)
    cmd = [cli, escape(name)] + extra + ["--reporter", "xml::out=" + out_xml]
    log = out_xml[:-4] + ".log"
    try:
        with open(log, "w") as f:
            r = subprocess.run(cmd, cwd=cwd, env=env, stdout=f, stderr=subprocess.STDOUT,
                               timeout=timeout)
        code = r.returncode
    except subprocess.TimeoutExpired:
        return "crashed", {}
    try:
        root = ET.parse(out_xml).getroot()
    except (ET.ParseError, FileNotFoundError):
        return "crashed", {}
    if code < 0:
        return "crashed", {}
    asserts = {}
    for e in root.iter("Expression"):
        key = "%s:%s" % (os.path.basename(e.get("filename", "?")), e.get("line", "?"))
        slot = asserts.setdefault(key, [0, 0])
        slot[0 if e.get("success") == "true" else 1] += 1
    overall = None
    for tc in root.iter("TestCase"):
        overall = tc.find("OverallResult")
    if overall is None:
        return "crashed", asserts
    if overall.get("success") != "true":
        return "failed", asserts
    if int(overall.get("skips", "0")) > 0 and not any(v[0] for v in asserts.values()):
        return "skipped", asserts
    return "passed", asserts


def main():
    a = parse_args()
    if not os.path.exists(a.stamp):
        print("SDFG_SKIPPED: no CTS build (%s); the archive ../shared/cts is absent" % a.stamp)
        return SKIP
    bin_dir = open(a.stamp).read().strip()
    cli = os.path.join(bin_dir, "conformance_cli")
    work = os.path.abspath(a.work)
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    # The layer, implicit, through a private XDG_DATA_HOME; the runtime alone gets an empty one
    # and the layer's disable variable as well.
    with_layer = os.path.join(work, "xdg-layer")
    layer_dir = os.path.join(with_layer, "openxr", "1", "api_layers", "implicit.d")
    os.makedirs(layer_dir)
    shutil.copy(a.layer_json, layer_dir)  # the build tree's manifest names an absolute library
    without = os.path.join(work, "xdg-empty")
    os.makedirs(without)

    base_env = dict(os.environ)
    base_env.update({
        "XR_RUNTIME_JSON": os.path.abspath(a.mock_json),
        "SDFG_MOCK_HAND_TRACKING": a.hand_tracking,
        "VK_ICD_FILENAMES": "/usr/share/vulkan/icd.d/lvp_icd.x86_64.json",
        "XR_LOADER_DEBUG": "none",
    })
    for k in ("XR_ENABLE_API_LAYERS", "XR_API_LAYER_PATH", a.layer_disable_env):
        base_env.pop(k, None)
    alone_env = dict(base_env, XDG_DATA_HOME=without, **{a.layer_disable_env: "1"})
    layer_env = dict(base_env, XDG_DATA_HOME=with_layer)

    cases = [c for c in a.cases.split(",") if c] or list_cases(cli, bin_dir, alone_env)
    if not cases:
        print("FAIL: the CTS listed no cases")
        return 1
    common = cts_args(a.graphics)
    offered = a.hand_tracking != "absent"
    # (name, env, extra args, baseline name)
    runs = [("runtime", alone_env, [], None)]
    if offered:
        runs.append(("runtime -E hand_tracking", alone_env, ["-E", "XR_EXT_hand_tracking"], None))
    runs += [
        ("layer idle", layer_env, [], "runtime"),
        ("layer -E hand_tracking", layer_env, ["-E", "XR_EXT_hand_tracking"],
         "runtime -E hand_tracking" if offered else "runtime"),
        ("layer -E auto_grasp", layer_env, ["-E", "XR_SDFG_auto_grasp"], "runtime"),
    ]
    results = {}
    print("CTS %s, mock hand tracking %s, %d cases" % (a.graphics, a.hand_tracking, len(cases)))
    for name, env, extra, _ in runs:
        start = time.time()
        res = {}
        tag = name.replace(" ", "_").replace("-", "")
        for i, case in enumerate(cases):
            out = os.path.join(work, "%s-%03d.xml" % (tag, i))
            res[case] = run_case(cli, bin_dir, env, case, common + extra, out, a.case_timeout)
        results[name] = res
        counts = {s: sum(1 for v in res.values() if v[0] == s)
                  for s in ("passed", "failed", "skipped", "crashed")}
        print("%-26s passed %3d  failed %3d  skipped %3d  crashed %3d  (%.0f s)" % (
            name, counts["passed"], counts["failed"], counts["skipped"], counts["crashed"],
            time.time() - start))
        for case, (status, _) in sorted(res.items()):
            if status in ("failed", "crashed"):
                print("    %s: %s" % (status, case))

    regressions = []
    for name, _, _, baseline in runs:
        if baseline is None:
            continue
        for case in cases:
            b_status, b_asserts = results[baseline][case]
            l_status, l_asserts = results[name][case]
            if b_status == "passed" and l_status != "passed":
                regressions.append("%s: case '%s' %s (passes on the runtime alone)" %
                                   (name, case, l_status))
            for key, (b_pass, b_fail) in b_asserts.items():
                if b_pass > 0 and b_fail == 0 and l_asserts.get(key, [0, 0])[1] > 0:
                    regressions.append("%s: case '%s' assertion %s fails (passes on the runtime "
                                       "alone)" % (name, case, key))
    for r in regressions:
        print("REGRESSION " + r)
    if regressions:
        print("FAIL: %d regressions with the layer (logs in %s)" % (len(regressions), work))
        return 1
    print("PASS: every case and assertion that passes on the runtime alone passes with the layer")
    return 0


if __name__ == "__main__":
    sys.exit(main())
