#!/usr/bin/env python3
"""dbc_decode.py DBC CAPTURE [POSES] → JSON on stdout: the firmware's POSE and HEALTH records of a
`candump -L` capture decoded with the DBC alone (hal/can/mmlfw.dbc; no project code), as a robot's
integrator would. Classic records (POSE_P0..P5, HEALTH_P0..P4) are joined by their Tag; CAN FD
records are one frame each. With POSES (`mml-candev score --dump` output: "index status x y ..." per
pose, in arrival order) every DBC-decoded pose is compared with the codec's: status and x/y within
1 mm. Prints {"poses": n, "health": n, "status_counts": {...}, "last_health": {...},
"max_health": {...}, "matches_codec": true|false|null, "mismatches": n}."""
import json
import re
import sys

STATUS = {0: "searching", 1: "ambiguous", 2: "localized", 3: "outside-map", 4: "fault"}


def load_dbc(path):
    msgs, cur = {}, None
    for line in open(path, encoding="utf-8", errors="replace"):
        m = re.match(r"BO_ (\d+) (\w+): (\d+)", line)
        if m:
            cur = {"name": m.group(2), "len": int(m.group(3)), "signals": []}
            msgs[int(m.group(1))] = cur
            continue
        m = re.match(r"\s+SG_ (\w+)\s*:\s*(\d+)\|(\d+)@([01])([+-]) \(([^,]+),([^)]+)\)", line)
        if m and cur is not None:
            cur["signals"].append((m.group(1), int(m.group(2)), int(m.group(3)), m.group(4) == "1",
                                   m.group(5) == "-", float(m.group(6)), float(m.group(7))))
    return msgs


def decode(msg, data):
    raw = int.from_bytes(data, "little")
    out = {}
    for name, start, bits, little, signed, scale, offset in msg["signals"]:
        if not little:
            raise ValueError(f"{msg['name']}.{name}: big-endian signals are not used by mmlfw.dbc")
        if start + bits > 8 * len(data):
            continue
        v = (raw >> start) & ((1 << bits) - 1)
        if signed and v >> (bits - 1):
            v -= 1 << bits
        out[name] = v * scale + offset
    return out


def frames(path):
    # (ts) iface ID#DATA | ID##F DATA (FD: flags nibble first); error frames have bit 29 in the ID.
    for line in open(path):
        p = line.split()
        if len(p) < 3 or "#" not in p[2]:
            continue
        cid, _, rest = p[2].partition("#")
        if rest.startswith("#"):
            rest = rest[2:]  # FD flags nibble
        if rest.startswith("R"):
            continue
        cid = int(cid, 16)
        if cid & 0x20000000:
            continue
        yield cid & 0x1FFFFFFF, bytes.fromhex(rest)


def main():
    dbc = load_dbc(sys.argv[1])
    poses, health, parts = [], [], {}
    for cid, data in frames(sys.argv[2]):
        msg = dbc.get(cid)
        if msg is None:
            continue
        name = msg["name"]
        sig = decode(msg, data)
        for kind, n_parts, out in (("POSE", 6, poses), ("HEALTH", 5, health)):
            if name == kind + "_FD":
                out.append(sig)
            elif name.startswith(kind + "_P"):
                k = int(name[len(kind) + 2:])
                if k == 0:
                    parts[kind] = dict(sig)
                elif kind in parts and parts[kind].get("Tag") == sig.get("Tag"):
                    parts[kind].update(sig)
                    # layout 0 senders stop at P4; mmlfw (layout 2) sends P5 last
                    if k == n_parts - 1:
                        out.append(parts.pop(kind))
    counts = {}
    for p in poses:
        s = STATUS.get(int(p.get("Status", -1)), "invalid")
        counts[s] = counts.get(s, 0) + 1
    res = {"poses": len(poses), "health": len(health), "status_counts": counts,
           "last_health": health[-1] if health else None,
           "max_health": {k: max(h.get(k, 0) for h in health) for k in
                          ("CrcErrors", "LostSegments", "DroppedScans", "BusOff", "ScansProcessed", "ErrorFrames")}
           if health else None,
           "matches_codec": None, "mismatches": None}
    if len(sys.argv) > 3:
        ref = [l.split() for l in open(sys.argv[3]) if l.strip()]
        # The codec's dump leaves out the laser-timeout repeats (status fault, same scan id).
        dbc_poses, last = [], None
        for p in poses:
            if last is not None and p.get("ScanId") == last.get("ScanId") and int(p.get("Status", -1)) == 4:
                continue
            dbc_poses.append(p)
            last = p
        bad = abs(len(ref) - len(dbc_poses))
        for r, p in zip(ref, dbc_poses):
            if (r[1] != STATUS.get(int(p["Status"]), "invalid") or abs(float(r[2]) - p["X"]) > 1.5e-3
                    or abs(float(r[3]) - p["Y"]) > 1.5e-3):
                bad += 1
        res["matches_codec"] = bad == 0 and len(ref) > 0
        res["mismatches"] = bad
    json.dump(res, sys.stdout)
    print()


if __name__ == "__main__":
    main()
