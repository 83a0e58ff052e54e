"""The Python module: arrays in and out, errors as exceptions, threads."""
import gc
import json
import os
import subprocess
import sys
import threading

import numpy as np
import pytest

import nphand


def test_version_and_asset():
    assert nphand.__version__.count(".") == 2
    assert os.path.isfile(os.path.join(nphand.default_asset_dir(), "right.glb"))
    assert len(nphand.KEYPOINT_NAMES) == 21 and len(nphand.DOF_NAMES) == 21


def test_render_gives_arrays(hand):
    images = nphand.render(hand, "fist", azimuth=30, width=200, height=150)
    assert images["rgb"].shape == (150, 200, 3) and images["rgb"].dtype == np.uint8
    assert images["labels"].shape == (150, 200) and images["labels"].dtype == np.uint8
    assert images["depth"].dtype == np.float32
    assert images["keypoints_2d"].shape == (21, 2) and images["keypoints_2d"].dtype == np.float64
    assert images["keypoints_3d"].shape == (21, 3)
    # The keypoints lie in the picture, on the hand's pixels' side of the camera.
    inside = (images["keypoints_2d"] >= 0).all() and (images["keypoints_2d"][:, 0] < 200).all()
    assert inside and (images["keypoints_3d"][:, 2] > 0).all()
    assert (images["labels"] > 0).sum() > 500
    # The keypoints are the model's at the rendered pose.
    local = hand.keypoints(images["rotation"], images["angles"])
    assert np.allclose(local, images["keypoints_3d"] - images["keypoints_3d"][0], atol=1e-9)
    # Angles given as an array; a grasp with its object.
    again = nphand.render(hand, nphand.articulation("fist"), azimuth=30, width=200, height=150)
    assert np.array_equal(again["rgb"], images["rgb"])
    grasp = nphand.render(hand, grasp="large_diameter")
    assert (grasp["labels"] == 2).sum() > 0, "the object's pixels"


def test_a_rendered_frame_round_trip(hand, tiny, frames):
    db, index = tiny
    estimator = nphand.Estimator(db, index, hand, k=40, faces=False)
    for frame in frames:
        result = estimator.process(frame["rgb"], frame["time_s"])
        assert result.detected, result.reason
        assert result.keypoints_2d.shape == (21, 2) and result.keypoints_2d.dtype == np.float64
        assert result.keypoints_3d.shape == (21, 3) and result.keypoints_hand.shape == (21, 3)
        assert result.rotation.shape == (3, 3)
        assert np.allclose(result.rotation @ result.rotation.T, np.eye(3), atol=1e-9)
        assert result.angles.shape == (21,)
        # A 24-view database places the hand, not its fine pose: the true middle knuckle lies
        # in the found hand's box, and the wrist and the knuckles near the true ones (the
        # fingertips, at the fingers' ends, swing with the pose the coarse views miss).
        x, y, w, h = result.box
        mx, my = frame["keypoints_2d"][9]
        assert x <= mx < x + w and y <= my < y + h
        errors = np.linalg.norm(result.keypoints_2d - frame["keypoints_2d"], axis=1)
        assert errors[[0, 5, 9, 13, 17]].mean() < 0.5 * max(w, h) and errors.mean() < max(w, h)
        assert result.ms > 0


def test_smoothing_is_on_by_default_and_can_be_turned_off(hand, tiny, frames):
    db, index = tiny
    smooth = nphand.Estimator(db, index, hand, k=40, faces=False)
    raw = nphand.Estimator(db, index, hand, k=40, faces=False, smooth=False)
    steps = []
    for frame in frames:
        a = smooth.process(frame["rgb"], frame["time_s"])
        b = raw.process(frame["rgb"], frame["time_s"])
        assert a.detected and b.detected
        steps.append(np.abs(a.keypoints_3d - b.keypoints_3d).max())
    # The first frame of a track is as it comes; later ones are pulled towards the last.
    assert steps[0] < 1e-12
    assert max(steps[1:]) > 1e-6


def test_the_estimate_is_the_modes_mean_unless_asked_for_the_best_alone(hand, tiny, frames):
    db, index = tiny
    mean = nphand.Estimator(db, index, hand, k=40, faces=False, smooth=False)
    best = nphand.Estimator(db, index, hand, k=40, faces=False, smooth=False, mode_mean=0.0)
    averaged = 0
    for frame in frames:
        a = mean.process(frame["rgb"], frame["time_s"])
        b = best.process(frame["rgb"], frame["time_s"])
        assert a.detected and b.detected
        assert b.mean_of == 1
        averaged += a.mean_of > 1
    assert averaged > 0
    with pytest.raises(nphand.Error, match="the mode's mean must reach within"):
        nphand.Estimator(db, index, hand, mode_mean=-1.0)


def test_the_refinement_says_what_it_did_and_measures_proportions_when_asked(hand, tiny, frames):
    db, index = tiny
    plain = nphand.Estimator(db, index, hand, k=40, faces=False)
    refined = nphand.Estimator(db, index, hand, k=40, faces=False, refine=True,
                               refine_move=["place", "wrist", "proportions"])
    for frame in frames:
        a = plain.process(frame["rgb"], frame["time_s"])
        b = refined.process(frame["rgb"], frame["time_s"])
        assert a.detected and b.detected
        assert a.proportions is None and not a.refined
        assert set(b.proportions) == {"length", "width", "held"}
        # Until the width is held the hand is the database's.
        assert b.proportions["held"] or b.proportions["width"] == b.proportions["length"]
    with pytest.raises(nphand.Error, match="unknown refinement move 'thumb'"):
        nphand.Estimator(db, index, hand, refine=True, refine_move=["thumb"])


def test_errors_are_exceptions_with_the_clis_message(tmp_path):
    bad = tmp_path / "bad.db"
    bad.write_bytes(b"garbage")
    with pytest.raises(nphand.Error) as error:
        nphand.Database(bad)
    assert "not an nphand database" in str(error.value)
    binary = os.environ.get("NPHAND_BINARY")
    if binary:
        cli = subprocess.run([binary, "db", "info", str(bad)], capture_output=True, text=True)
        assert cli.returncode == 1
        assert cli.stderr.strip() == "nphand: error: " + str(error.value)
    with pytest.raises(nphand.Error, match="right or left"):
        nphand.HandModel("middle")
    with pytest.raises(nphand.Error, match="hand mesh not found"):
        nphand.HandModel("right", asset_dir=tmp_path)


def test_bad_frames_are_refused(hand, tiny):
    db, index = tiny
    estimator = nphand.Estimator(db, index, hand, faces=False)
    with pytest.raises(ValueError, match="H x W x 3 uint8 BGR"):
        estimator.process(np.zeros((48, 64), np.uint8))
    with pytest.raises(nphand.Error, match="estimator: "):
        nphand.Estimator(db, index, hand, k=0)
    with pytest.raises(nphand.Error, match="track's views must be within 0..64"):
        nphand.Estimator(db, index, hand, track_views=65)
    # A frame with nothing in it is "no hand", not an error.
    assert not estimator.process(np.zeros((48, 64, 3), np.uint8)).detected
    with pytest.raises(nphand.Error, match="width and height above 0"):
        estimator.process(np.zeros((48, 64, 3), np.uint8), roi=(0, 0, 0, 5))
    with pytest.raises(nphand.Error, match="does not meet the 64 x 48 frame"):
        estimator.process(np.zeros((48, 64, 3), np.uint8), roi=(70, 0, 5, 5))


def test_a_region_of_interest_confines_the_search(hand, tiny, frames):
    db, index = tiny
    estimator = nphand.Estimator(db, index, hand, k=40, faces=False, smooth=False)
    frame = frames[0]["rgb"]
    whole = estimator.process(frame)
    assert whole.detected, whole.reason
    x, y, w, h = whole.box
    estimator.reset()
    assert estimator.process(frame, roi=(x - 5, y - 5, w + 10, h + 10)).box == whole.box
    estimator.reset()
    corner = estimator.process(frame, roi=(0, 0, 4, 4))
    assert not corner.detected and corner.reason == "no skin-coloured region within the region of interest"


def test_two_threads_each_drive_their_own_estimator(hand, tiny, frames):
    db, index = tiny

    def run(out):
        estimator = nphand.Estimator(db, index, hand, k=40, faces=False)
        for _ in range(5):
            estimator.reset()
            out.append([estimator.process(f["rgb"], f["time_s"]).keypoints_3d for f in frames])

    alone = []
    run(alone)
    outs = [[], []]
    threads = [threading.Thread(target=run, args=(out,)) for out in outs]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for out in outs:
        assert len(out) == 5
        for run_keypoints in out:
            for a, b in zip(run_keypoints, alone[0]):
                assert np.array_equal(a, b)


def test_the_example_estimates_a_video(hand, frames, tmp_path):
    db_path = tmp_path / "example.db"
    nphand.build_database(hand, db_path, grasps=[1], directions=24, image_size=96, threads=1)
    example_db = nphand.Database(db_path)
    nphand.Index.build(example_db, "exact").save(str(db_path) + ".idx", example_db)
    video = nphand.VideoWriter(tmp_path / "clip.mp4", 30.0)
    for frame in frames:
        video.write(frame["rgb"])
    video.finish()
    read = [item["frame"] for item in nphand.FrameSource(str(tmp_path / "clip.mp4"))]
    assert len(read) == len(frames) and read[0].shape == frames[0]["rgb"].shape
    script = os.path.join(os.path.dirname(__file__), "..", "..", "examples", "estimate_video.py")
    run = subprocess.run([sys.executable, script, str(tmp_path / "clip.mp4"), "--db", str(db_path),
                          "--overlay", str(tmp_path / "drawn.mp4")], capture_output=True, text=True,
                         env=dict(os.environ))
    assert run.returncode == 0, run.stderr
    lines = [json.loads(line) for line in run.stdout.splitlines()]
    assert [line["frame"] for line in lines] == list(range(len(frames)))
    assert all(len(line["keypoints_3d_camera_m"]) == 21 for line in lines if line["detected"])
    assert sum(line["detected"] for line in lines) >= len(frames) - 1
    assert (tmp_path / "drawn.mp4").stat().st_size > 0
    missing = subprocess.run([sys.executable, script, str(tmp_path / "clip.mp4"), "--db", str(tmp_path / "none.db")],
                             capture_output=True, text=True)
    assert missing.returncode == 1 and "estimate_video: error: " in missing.stderr


def test_an_index_keeps_its_database_alive(hand, tmp_path):
    path = tmp_path / "kept.db"
    nphand.build_database(hand, path, grasps=[1], directions=8, image_size=96, threads=1)
    # Neither index's own database object is kept here: the index keeps it alive.
    index = nphand.Index.build(nphand.Database(path), "hnswlib-sq8")
    gc.collect()
    db = nphand.Database(path)
    index.save(str(path) + ".idx", db)
    loaded = nphand.Index(nphand.Database(path), str(path) + ".idx")
    gc.collect()
    frame = nphand.render(hand, grasp="large_diameter", width=320, height=240)
    result = nphand.Estimator(db, loaded, hand, k=10, faces=False).process(frame["rgb"])
    assert result.status != "no_skin", "the hand was looked up in the index"


def test_the_database_holds_the_gestures_unless_told_otherwise(hand, tmp_path):
    def build(name, **gestures):
        return nphand.build_database(hand, tmp_path / name, grasps=[1], directions=8, image_size=96, threads=1,
                                     **gestures)
    grasp_only = build("none.db", gestures=[])
    assert grasp_only == 1 * 5 * 2 * 8
    assert build("none_named.db", gestures=["none"]) == grasp_only
    assert build("peace.db", gestures=["peace"]) == grasp_only + 5 * 8
    assert build("all.db") == grasp_only + 16 * 5 * 8
    with pytest.raises(nphand.Error, match="unknown gesture 'wave'"):
        build("wave.db", gestures=["wave"])
