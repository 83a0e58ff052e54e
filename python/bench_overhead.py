#!/usr/bin/env python3
"""What calling nphand from Python costs over C++, per frame: a benchmark, not a test.

Renders frames of a sequence like `nphand bench pipeline` (640x480, a hand with a bare
forearm grasping an object, cluttered background), runs the estimator on each from Python
(the frame in, every result array out) and compares the wall time of each call with the
estimator's own time on the frame (Result.ms, measured inside C++). Prints the median and
mean per-frame overhead.

    PYTHONPATH=build/python python3 python/bench_overhead.py --db out/nphand.db [--frames 300]
"""
import argparse
import statistics
import sys
import time

import nphand


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--db", default="out/nphand.db")
    parser.add_argument("--frames", type=int, default=300)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    db = nphand.Database(args.db)
    index = nphand.Index(db, args.db + ".idx")
    hand = nphand.HandModel("right")
    sequence = nphand.Sequence(hand, grasp=1, frames=args.frames, background="clutter", seed=args.seed)
    frames = [sequence.render(i) for i in range(len(sequence))]
    estimator = nphand.Estimator(db, index, hand, hand_length=sequence.hand_length)
    for frame in frames[:20]:  # warm the caches
        estimator.process(frame["rgb"], frame["time_s"])
    estimator.reset()
    walls, insides = [], []
    for frame in frames:
        start = time.perf_counter()
        result = estimator.process(frame["rgb"], frame["time_s"])
        arrays = (result.keypoints_2d, result.keypoints_3d, result.rotation, result.angles)
        walls.append((time.perf_counter() - start) * 1000.0)
        insides.append(result.ms)
        del arrays
    overheads = [w - i for w, i in zip(walls, insides)]
    print(f"frames {len(frames)}: per frame, C++ {statistics.median(insides):.3f} ms median "
          f"({statistics.mean(insides):.3f} mean); from Python {statistics.median(walls):.3f} ms median "
          f"({statistics.mean(walls):.3f} mean)")
    print(f"overhead: {statistics.median(overheads) * 1000:.1f} us median, "
          f"{100 * statistics.mean(overheads) / statistics.mean(insides):.2f} % of the mean frame")
    return 0


if __name__ == "__main__":
    sys.exit(main())
