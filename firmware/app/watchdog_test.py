#!/usr/bin/env python3
"""mmlfw's systemd notifications against a real AF_UNIX datagram socket (CTest mmlfw_watchdog_test).

The test is the service manager's side: it binds NOTIFY_SOCKET, starts mmlfw with WATCHDOG_USEC
as systemd would (WatchdogSec=), and reads the datagrams with their arrival times.
  run 1, healthy: READY=1 after start-up, STATUS= with the status (and the laser-timeout fault the
         silent laser raises), WATCHDOG=1 at least every half period until SIGTERM, STOPPING=1.
  run 2, --test-stall-after: WATCHDOG=1 as before until the loop stalls, then none for many
         watchdog periods while the process is still alive (systemd would kill and restart it).
  With --sickdev MML_SICKDEV --mapc MML_MAPC (and socat and the aces log of ../shared/data), scans
  flow: the SICK device model streams aces telegrams at 75 Hz over a socat pty pair.
  run 3, scans within the deadline (odometry localizer): WATCHDOG=1 throughout while stepping.
  run 4, every step late (mml-track with MML inline, step_deadline_ms = 0.1): the loop cycles and
         steps, but WATCHDOG=1 stops (systemd would restart a firmware that keeps no deadline).
  watchdog_test.py MMLFW [--summary FILE] [--sickdev PATH --mapc PATH [--data DIR]]
"""
import os, shutil, signal, socket, subprocess, sys, tempfile, time

PERIOD_S = 0.5  # WATCHDOG_USEC: the firmware checks every 0.25 s


SILENT_LASER = ("laser = serial:/dev/ptmx\nodometry = none\noutput = log\nlocalizer = odom\n"
                "workers = 1\narena_mib = 8\nlaser_timeout_ms = 300\n")


def run(mmlfw, work, name, extra, stall_at=None, seconds=3.0, conf_text=SILENT_LASER):
    path = os.path.join(work, name + ".sock")
    rx = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
    rx.bind(path)
    rx.settimeout(0.05)
    conf = os.path.join(work, name + ".conf")
    with open(conf, "w") as f:
        f.write(conf_text)
    env = dict(os.environ, NOTIFY_SOCKET=path, WATCHDOG_USEC=str(int(PERIOD_S * 1e6)))
    env.pop("WATCHDOG_PID", None)
    err = open(os.path.join(work, name + ".err"), "w")
    t0 = time.monotonic()
    p = subprocess.Popen([mmlfw, "--config", conf] + extra, env=env, stdout=subprocess.DEVNULL, stderr=err)
    msgs = []
    while time.monotonic() - t0 < seconds:
        try:
            data = rx.recv(4096)
            msgs.append((time.monotonic() - t0, data.decode()))
        except socket.timeout:
            pass
    alive = p.poll() is None
    p.send_signal(signal.SIGTERM)
    try:
        rc = p.wait(timeout=10)
    except subprocess.TimeoutExpired:
        p.kill(); rc = p.wait()
    t_end = time.monotonic()
    while True:  # what arrived on the way out
        try:
            msgs.append((time.monotonic() - t0, rx.recv(4096).decode()))
        except socket.timeout:
            break
    rx.close(); os.unlink(path); err.close()
    return msgs, alive, rc, t_end - t0


def arg(name):
    return sys.argv[sys.argv.index(name) + 1] if name in sys.argv else None


def mmlfw_summary(path):
    import json
    for line in open(path):
        if line.startswith("mmlfw summary: "):
            return json.loads(line[len("mmlfw summary: "):])
    return {}


def scan_runs(mmlfw, work, check):
    """Runs 3 and 4 (scans through the SICK device model); None when they cannot run here."""
    sickdev, mapc = arg("--sickdev"), arg("--mapc")
    here = os.path.dirname(os.path.abspath(__file__))
    data = arg("--data") or os.environ.get("MMLFW_DATA_DIR") or os.path.join(here, "..", "..", "..", "shared", "data")
    why = None
    if not sickdev or not mapc:
        why = "no --sickdev/--mapc given"
    elif shutil.which("socat") is None:
        why = "socat not installed"
    elif not os.path.exists(os.path.join(data, "aces", "aces.clf.gz")):
        why = "aces log not found under " + data
    if why:
        print("SKIP - runs with scans: " + why)
        return None
    n_before = len(check.failures)
    # A 6 x 4 m room (a wrong map for aces: MML searches on every step and never fixes).
    W, H = 120, 80
    px = bytearray([254]) * (W * H)
    for x in range(10, 110):
        for y in (10, 69): px[y * W + x] = 0
    for y in range(10, 70):
        for x in (10, 109): px[y * W + x] = 0
    for y in range(10, 40): px[y * W + 50] = 0
    open(os.path.join(work, "room.pgm"), "wb").write(b"P5\n%d %d\n255\n" % (W, H) + bytes(px))
    open(os.path.join(work, "room.yaml"), "w").write("image: room.pgm\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\n"
                                                     "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n")
    mmap = os.path.join(work, "room.mmap")
    subprocess.run([mapc, "--relation-table", os.path.join(work, "room.yaml"), mmap], stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL, check=True)
    results = []
    for name, body, feeds_expected in [
            ("scans_odom", "localizer = odom\n", True),
            ("scans_late", "localizer = mml-track\nmap = %s\nglobal_context = inline\nstep_deadline_ms = 0.1\n"
             "arena_mib = 64\n" % mmap, False)]:
        pty_a, pty_b = os.path.join(work, name + "_ttyA"), os.path.join(work, name + "_ttyB")
        sp = subprocess.Popen(["socat", "pty,raw,echo=0,link=" + pty_a, "pty,raw,echo=0,link=" + pty_b],
                              stderr=subprocess.DEVNULL)
        for _ in range(100):
            if os.path.exists(pty_a) and os.path.exists(pty_b): break
            time.sleep(0.05)
        dev = subprocess.Popen([sickdev, "--device", pty_a, "--dataset", "aces", "--count", "300", "--rate", "75",
                                "--wait", "10"], env=dict(os.environ, MMLFW_DATA_DIR=data),
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        conf = ("laser = serial:%s@500000\nodometry = none\noutput = log\nworkers = 1\nlog_level = warning\n" % pty_b
                + body + ("arena_mib = 16\n" if "arena_mib" not in body else ""))
        msgs, alive, rc, _ = run(mmlfw, work, name, [], seconds=3.5, conf_text=conf)
        dev.kill(); dev.wait(); sp.kill(); sp.wait()
        s = mmlfw_summary(os.path.join(work, name + ".err"))
        steps, missed = s.get("scans_processed", 0), s.get("deadline_misses", 0)
        t_ready = next((t for t, m in msgs if m == "READY=1"), 0.0)
        dogs = [t for t, m in msgs if m == "WATCHDOG=1"]
        late_dogs = [t for t in dogs if t > t_ready + 1.2]  # after the first scans arrived
        check("%s: alive and stepping scans (%d steps, %d late)" % (name, steps, missed),
              alive and rc == 0 and steps >= (20 if feeds_expected else 5))
        if feeds_expected:
            check("%s: WATCHDOG=1 throughout while every step keeps the deadline" % name,
                  missed < steps and len(late_dogs) >= 6, "%d feeds after %.1f s" % (len(late_dogs), t_ready + 1.2))
        else:
            check("%s: every step late, WATCHDOG=1 withheld though the loop cycles" % name,
                  missed == steps and not late_dogs, "%d feeds in all, %d after %.1f s" % (len(dogs), len(late_dogs),
                                                                                        t_ready + 1.2))
        results.append(len(check.failures) == n_before)
        n_before = len(check.failures)
    return tuple(int(r) for r in results)


def main():
    mmlfw = sys.argv[1]
    summary = sys.argv[sys.argv.index("--summary") + 1] if "--summary" in sys.argv else None
    work = tempfile.mkdtemp(prefix="mmlfw_watchdog_")
    failures = []

    def check(name, ok, detail=""):
        print(("ok   - " if ok else "FAIL - ") + name + (": " + detail if detail else ""))
        if not ok:
            failures.append(name)
    check.failures = failures

    # --- run 1: healthy -----------------------------------------------------------------------
    msgs, alive, rc, _ = run(mmlfw, work, "healthy", [], seconds=3.0)
    texts = [m for _, m in msgs]
    dogs = [t for t, m in msgs if m == "WATCHDOG=1"]
    check("healthy: READY=1 is the first message", bool(texts) and texts[0] == "READY=1", repr(texts[:2]))
    status = [m for m in texts if m.startswith("STATUS=")]
    check("healthy: STATUS= with the localization status", any(m.startswith("STATUS=searching") or
          m.startswith("STATUS=fault") for m in status), repr(status[:3]))
    check("healthy: STATUS= names the silent laser's fault", any("laser-timeout" in m for m in status), repr(status))
    # Times from READY=1 (start-up is slower under the sanitizers; the loop's clock starts there).
    t_ready = next((t for t, m in msgs if m == "READY=1"), 0.0)
    gaps = [b - a for a, b in zip([t_ready] + dogs, dogs)]
    check("healthy: WATCHDOG=1 throughout", len(dogs) >= 4 and dogs[-1] > 3.0 - PERIOD_S,
          "%d feeds from %.2f s (READY) to %.2f s" % (len(dogs), t_ready, dogs[-1] if dogs else -1))
    check("healthy: never a gap of a watchdog period", bool(gaps) and max(gaps) < PERIOD_S,
          "largest gap %.3f s" % (max(gaps) if gaps else -1))
    check("healthy: alive until SIGTERM, exit 0", alive and rc == 0, "alive %s, exit %s" % (alive, rc))
    check("healthy: STOPPING=1 on the way out", texts[-1:] == ["STOPPING=1"], repr(texts[-2:]))
    healthy_ok = not failures

    # --- run 2: the loop stalls -----------------------------------------------------------------
    n_before = len(failures)
    stall_at = 1.5
    msgs, alive, rc, _ = run(mmlfw, work, "stall", ["--test-stall-after", str(stall_at)], seconds=5.0)
    texts = [m for _, m in msgs]
    dogs = [t for t, m in msgs if m == "WATCHDOG=1"]
    check("stall: READY=1 first", bool(texts) and texts[0] == "READY=1", repr(texts[:2]))
    check("stall: fed before the stall", len(dogs) >= 3, "%d feeds" % len(dogs))
    last = dogs[-1] if dogs else 0.0
    t_ready = next((t for t, m in msgs if m == "READY=1"), 0.0)
    # The loop stalls stall_at after READY=1: the last feed comes within one check interval (plus
    # scheduling slack) of it, then none for at least three watchdog periods.
    check("stall: WATCHDOG=1 stops when the loop stalls", bool(dogs) and last < t_ready + stall_at + PERIOD_S and
          5.0 - last > 3 * PERIOD_S, "READY at %.2f s, last feed at %.2f s, %.2f s of silence" % (t_ready, last, 5.0 - last))
    check("stall: the process is still alive (hung, not exited)", alive)
    stall_ok = len(failures) == n_before

    scans = scan_runs(mmlfw, work, check)

    if summary:
        with open(summary, "w") as f:
            f.write("healthy_ok %d\nstall_stops_watchdog %d\n" % (healthy_ok, stall_ok))
            if scans is not None:
                f.write("scans_fed %d\nlate_steps_stop_watchdog %d\n" % scans)
    if not failures:
        shutil.rmtree(work, ignore_errors=True)
    else:
        print("watchdog_test: firmware logs in " + work)
    print("watchdog_test: " + ("all passed" if not failures else "FAILED: " + ", ".join(failures)))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
