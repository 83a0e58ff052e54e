#!/usr/bin/env python3
"""Hand poses in a video with nphand's Python module: one JSON line per frame on stdout,
and (with --overlay) the video with each found hand's skeleton drawn on it.

From a clone, after scripts/build.sh and the database (scripts/demo.sh makes it):
    PYTHONPATH=build/python python3 examples/estimate_video.py VIDEO --db out/nphand.db --overlay out/drawn.mp4
VIDEO may be a video file, an image folder or a camera index; --opencv reads it with
OpenCV's Python reader (cv2, python3-opencv) instead of nphand's own.
"""
import argparse
import json
import sys

import nphand


def frames_from_opencv(path):
    import cv2  # only for --opencv

    capture = cv2.VideoCapture(path)
    if not capture.isOpened():
        raise nphand.Error(f"{path}: OpenCV cannot open it")
    fps = capture.get(cv2.CAP_PROP_FPS) or 30.0
    index = 0
    while True:
        ok, frame = capture.read()
        if not ok:
            return
        yield {"frame": frame, "time_s": index / fps, "error": "", "name": ""}
        index += 1


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("video", help="video file, image folder or camera index")
    parser.add_argument("--db", default="out/nphand.db", help="database file (nphand db build)")
    parser.add_argument("--index", help="index file (default: the database's path + .idx)")
    parser.add_argument("--hand", default="right", choices=["right", "left", "auto"])
    parser.add_argument("--hand-length", type=float, default=0.18, help="wrist to middle fingertip, metres")
    parser.add_argument("--refine", action="store_true", help="refine each pose against the hand's silhouette")
    parser.add_argument("--overlay", help="write the drawn frames to this .mp4")
    parser.add_argument("--max-frames", type=int, default=0, help="stop after this many frames (0: all)")
    parser.add_argument("--opencv", action="store_true", help="read the video with cv2 instead of nphand")
    args = parser.parse_args()

    try:
        db = nphand.Database(args.db)
        index = nphand.Index(db, args.index or args.db + ".idx")
        estimator = nphand.Estimator(db, index, nphand.HandModel("right"), hand=args.hand,
                                     hand_length=args.hand_length, refine=args.refine)
        source = frames_from_opencv(args.video) if args.opencv else nphand.FrameSource(args.video)
        writer = nphand.VideoWriter(args.overlay, getattr(source, "fps", 30.0)) if args.overlay else None
        detected = frames = 0
        for item in source:
            if args.max_frames and frames == args.max_frames:
                break
            line = {"frame": frames, "time_s": item["time_s"]}
            if item["frame"] is None:
                line.update(detected=False, status="unreadable", reason=item["error"])
            else:
                result = estimator.process(item["frame"], item["time_s"])
                line.update(detected=result.detected, status=result.status)
                picture = item["frame"]
                if result.detected:
                    detected += 1
                    line.update(hand=result.hand, confidence=result.confidence,
                                keypoints_2d_px=result.keypoints_2d.round(2).tolist(),
                                keypoints_3d_camera_m=result.keypoints_3d.round(5).tolist(),
                                joint_angles_rad=result.angles.round(5).tolist())
                    picture = nphand.draw(picture, result.keypoints_2d)
                else:
                    line["reason"] = result.reason
                if writer is not None:
                    writer.write(picture)
            print(json.dumps(line), flush=True)
            frames += 1
        if writer is not None and writer.frames > 0:
            writer.finish()
        print(f"estimate_video: {detected} of {frames} frames with a hand", file=sys.stderr)
    except nphand.Error as error:
        print(f"estimate_video: error: {error}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
