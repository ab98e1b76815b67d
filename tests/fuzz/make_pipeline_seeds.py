#!/usr/bin/env python3
"""Writes the seed inputs of fuzz_pipeline (corpus/pipeline/*.bin).

FuzzedDataProvider takes integers from the END of the input, one byte per value here, so a seed is
the list of consumed bytes reversed. Each seed is a plausible stream (quiet unit at 100 Hz) with one
kind of trouble in it, so the fuzzer starts from inputs that reach detection and isolation.
"""
import os
import random

HERE = os.path.dirname(os.path.abspath(__file__))


def epoch(out, n, rates, dt_kind=0, sample_kinds=None, dt_bytes=()):
    out += [0, dt_kind]  # op byte < 240: an epoch; dt byte < 224: the nominal 10 ms
    out += list(dt_bytes)  # dt byte >= 224: 4 bytes of a step in [-2 s, 2 s]
    for i in range(n):
        kind = 0 if sample_kinds is None else sample_kinds[i]
        out.append(kind)
        if kind < 200:
            out.append(rates[i] & 0xFF)  # int8 rate in 1e-4 deg/s
    out.append(1)  # reference choice: (1 % 16) != 0, no reference


def seed(name, n, body):
    rnd = random.Random(name)
    out = [n - 3, 4]  # n gyros (3 + b % 4), switches: sample_period 0.01
    body(out, n, rnd)
    with open(os.path.join(HERE, "corpus", "pipeline", name + ".bin"), "wb") as f:
        f.write(bytes(reversed(out)))


def noise(rnd, n):
    return [rnd.randint(-3, 3) for _ in range(n)]


def quiet(out, n, rnd):
    for _ in range(400):
        epoch(out, n, noise(rnd, n))


def bias_step(out, n, rnd):
    for k in range(400):
        r = noise(rnd, n)
        if k >= 200:
            r[1] += 40  # gyro 2: +0.004 deg/s
        epoch(out, n, r)


def stuck(out, n, rnd):
    for k in range(400):
        r = noise(rnd, n)
        if k >= 150:
            r[0] = 5
        epoch(out, n, r)


def dropout_invalid(out, n, rnd):
    for k in range(400):
        kinds = [0] * n
        if 100 <= k < 300:
            kinds[2] = 210  # absent
        if 200 <= k < 260:
            kinds[0] = 250  # any double; with the next byte a NaN/inf/huge choice
        r = noise(rnd, n)
        out += [0, 0]
        for i in range(n):
            out.append(kinds[i])
            if kinds[i] < 200:
                out.append(r[i] & 0xFF)
            elif kinds[i] >= 220:
                out.append(0)  # any_double: case 0 = NaN
        out.append(1)


def commands_and_time(out, n, rnd):
    for k in range(300):
        if k == 50:
            out += [240, 2]  # exclude gyro (-1 + 2 % (n + 3)) = 1
        if k == 120:
            out += [241, 2]  # reinstate 1
        if k == 200:
            out += [242, 0]  # reset command
        if k == 80:
            epoch(out, n, noise(rnd, n), dt_kind=224, dt_bytes=(0, 0, 0, 0))  # 2 s backwards
        elif k == 81:
            epoch(out, n, noise(rnd, n), dt_kind=224, dt_bytes=(0xEE, 0x6B, 0x28, 0x00))  # forwards
        else:
            epoch(out, n, noise(rnd, n))


os.makedirs(os.path.join(HERE, "corpus", "pipeline"), exist_ok=True)
seed("quiet4", 4, quiet)
seed("bias_step4", 4, bias_step)
seed("stuck5", 5, stuck)
seed("dropout_invalid4", 4, dropout_invalid)
seed("commands3", 3, commands_and_time)
