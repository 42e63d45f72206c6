"""The Gymnasium-like spaces."""

import numpy as np

from psc.spaces import Box, Discrete, MultiDiscrete


def test_box():
    box = Box(0, 1, (2, 3), np.uint8, seed=0)
    sample = box.sample()
    assert sample.shape == (2, 3) and sample.dtype == np.uint8
    assert box.contains(sample) and sample in box
    assert not box.contains(np.full((2, 3), 2, dtype=np.uint8))
    assert not box.contains(np.zeros((3, 2), dtype=np.uint8))
    assert not box.contains(np.zeros((2, 3), dtype=np.float32))


def test_discrete():
    space = Discrete(5, seed=0)
    samples = {int(space.sample()) for _ in range(200)}
    assert samples == {0, 1, 2, 3, 4}
    assert space.contains(4) and not space.contains(5) and not space.contains(-1)
    assert not space.contains(1.0)


def test_multi_discrete_and_seeding():
    space = MultiDiscrete([3, 3, 3, 3], seed=1)
    sample = space.sample()
    assert sample.shape == (4,) and space.contains(sample)
    assert not space.contains([0, 0, 0, 3])
    space.seed(7)
    first = space.sample()
    space.seed(7)
    np.testing.assert_array_equal(space.sample(), first)
