#!/usr/bin/python3
"""Per-session error of a saved map (docs/map_format.md) whose sessions are
simulated passes of one world (`saloam simulate --passes ... --pass K`).

  session_ate.py MAP SEQ_0 [SEQ_1 ...]
      SEQ_s: the sequence folder session s was made from. Prints, per
      session, the keyframe position RMSE / max [m] after one SE(3)
      alignment of every linked keyframe to the truth (the common frame),
      and with no alignment (the map frame is the truth's: both are the
      first keyframe's LiDAR frame),
      and the cross-session loop edges whose relative pose is not the
      truth's (0.5 m, 2 degrees, as loops are judged).
  session_ate.py MAP SEQ --pieces A:B,C:D
      A map of one run through the whole route (SEQ): the error of the
      keyframes whose route pose index (first pass index + frame * stride)
      lies in each piece, after one alignment of all keyframes.

Reads the map's keyframes.bin and edges.bin (version 1 or 2) and each
SEQ's poses.txt, calib.txt (Tr) and simulation.yaml (origin, passes,
stride). Uses numpy only.
"""
import argparse
import json
import os
import struct
import sys

import numpy as np


def read_table(path, kind):
    data = open(path, 'rb').read()
    if data[:8] != b'SALOAMAP':
        sys.exit(f'{path}: not a saloam map file')
    version, table, count = struct.unpack_from('<IIQ', data, 8)
    if table != kind:
        sys.exit(f'{path}: table kind {table}, expected {kind}')
    return data, version, count


def pose(values):
    T = np.eye(4)
    T[:3, :] = np.array(values).reshape(3, 4)
    return T


def read_keyframes(folder):
    data, version, count = read_table(os.path.join(folder, 'keyframes.bin'), 1)
    size = 220 if version >= 2 else 216
    out = []
    for k in range(count):
        at = 24 + k * size
        frame = struct.unpack_from('<Q', data, at)[0]
        p = struct.unpack_from('<12d', data, at + 24)
        session = struct.unpack_from('<I', data, at + 216)[0] if version >= 2 else 0
        out.append((frame, pose(p), session))
    return out


def read_edges(folder):
    data, _, count = read_table(os.path.join(folder, 'edges.bin'), 2)
    out = []
    for e in range(count):
        at = 24 + e * 276
        a, b, kind = struct.unpack_from('<III', data, at)
        out.append((a, b, kind, pose(struct.unpack_from('<12d', data, at + 12))))
    return out


def read_sequence(seq):
    poses = [pose([float(x) for x in line.split()]) for line in open(os.path.join(seq, 'poses.txt')) if line.strip()]
    tr = np.eye(4)
    for line in open(os.path.join(seq, 'calib.txt')):
        if line.startswith('Tr:'):
            tr = pose([float(x) for x in line.split()[1:13]])
    yaml = {}
    for line in open(os.path.join(seq, 'simulation.yaml')):
        if ':' in line and not line.startswith('#'):
            key, value = line.split(':', 1)
            yaml[key.strip()] = value.strip()
    origin = pose([float(x) for x in yaml['origin'].split()])
    lidar = [np.linalg.inv(tr) @ (np.linalg.inv(poses[0]) @ P) @ tr for P in poses]
    return lidar, origin, yaml


def umeyama(est, ref):
    mu_e, mu_r = est.mean(0), ref.mean(0)
    U, _, Vt = np.linalg.svd((ref - mu_r).T @ (est - mu_e))
    S = np.eye(3)
    if np.linalg.det(U @ Vt) < 0:
        S[2, 2] = -1
    R = U @ S @ Vt
    return R, mu_r - R @ mu_e


def rotation_deg(T):
    return np.degrees(np.arccos(np.clip((np.trace(T[:3, :3]) - 1) / 2, -1, 1)))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('map')
    parser.add_argument('sequences', nargs='+')
    parser.add_argument('--pieces', help='A:B,... route pose ranges (a map of one run)')
    args = parser.parse_args()
    keyframes = read_keyframes(args.map)
    manifest = json.load(open(os.path.join(args.map, 'map.json')))
    linked = [s['linked'] for s in manifest.get('sessions', [{'linked': True}])]
    seqs = [read_sequence(s) for s in args.sequences]
    origin0 = seqs[0][1]
    truth, est, group = [], [], []
    for frame, T, session in keyframes:
        if not linked[session]:
            continue
        lidar, origin, yaml = seqs[session]
        truth.append(np.linalg.inv(origin0) @ origin @ lidar[frame])
        est.append(T)
        if args.pieces:
            first = int(yaml['passes'].split(',')[int(yaml.get('pass', 0))].split(':')[0]) if 'passes' in yaml else 0
            index = first + frame * int(yaml.get('stride', 1))
            group.append([i for i, p in enumerate(args.pieces.split(','))
                          if int(p.split(':')[0]) <= index < int(p.split(':')[1])])
        else:
            group.append([session])
    R, t = umeyama(np.array([T[:3, 3] for T in est]), np.array([T[:3, 3] for T in truth]))
    names = args.pieces.split(',') if args.pieces else [f'session {s}' for s in range(len(linked))]
    for label, R, t in (('aligned once', R, t), ('no alignment', np.eye(3), np.zeros(3))):
        err = np.array([np.linalg.norm(R @ e[:3, 3] + t - g[:3, 3]) for e, g in zip(est, truth)])
        for i, name in enumerate(names):
            sel = np.array([i in g for g in group])
            if sel.any():
                print(f'{label}: {name}: {sel.sum()} keyframes, RMSE {np.sqrt((err[sel] ** 2).mean()):.3f} m, '
                      f'max {err[sel].max():.3f} m')
        print(f'{label}: all: {len(err)} keyframes, RMSE {np.sqrt((err ** 2).mean()):.3f} m')
    if not args.pieces:
        sessions = [s for _, _, s in keyframes]
        true_loops = false_loops = 0
        for a, b, kind, Z in read_edges(args.map):
            if kind != 1 or sessions[a] == sessions[b]:
                continue
            ta = np.linalg.inv(origin0) @ seqs[sessions[a]][1] @ seqs[sessions[a]][0][keyframes[a][0]]
            tb = np.linalg.inv(origin0) @ seqs[sessions[b]][1] @ seqs[sessions[b]][0][keyframes[b][0]]
            D = np.linalg.inv(np.linalg.inv(ta) @ tb) @ Z
            ok = np.linalg.norm(D[:3, 3]) < 0.5 and rotation_deg(D) < 2.0
            true_loops += ok
            false_loops += not ok
        print(f'cross-session loop edges: {true_loops} true, {false_loops} false')


if __name__ == '__main__':
    main()
