"""Shared fixtures: one tiny database (grasp 1 and the gestures, 24 directions) and its exact index per run."""
import pytest

import nphand


@pytest.fixture(scope="session")
def hand():
    return nphand.HandModel("right")


@pytest.fixture(scope="session")
def tiny(tmp_path_factory, hand):
    path = tmp_path_factory.mktemp("db") / "tiny.db"
    entries = nphand.build_database(hand, path, grasps=[1], directions=24, image_size=96, threads=1)
    db = nphand.Database(path)
    assert len(db) == entries
    return db, nphand.Index.build(db, "exact")


@pytest.fixture(scope="session")
def frames(hand):
    sequence = nphand.Sequence(hand, grasp=1, frames=4, object_scale=1.0, background="plain", seed=3)
    return [sequence.render(i) for i in range(len(sequence))]
