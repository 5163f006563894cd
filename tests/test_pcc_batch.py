"""The batched PCC pose map: one call for many arcs, on all cores for large batches."""

import numpy as np
import pytest

import softrod
from softrod import pcc


def closed_form_tip(k, phi, length):
    """Tip position of an arc (docs/pcc.md): in its bending plane (1 - cos)/k and sin/k."""
    theta = k * length
    r = (1.0 - np.cos(theta)) / k
    return np.stack([r * np.cos(phi), r * np.sin(phi), np.sin(theta) / k], axis=-1)


@pytest.mark.parametrize("n", [7, 50_000])  # below and above the parallel threshold
def test_batched_poses_match_closed_form_and_single_calls(n):
    rng = np.random.default_rng(3)
    k = rng.uniform(0.5, 20.0, n)
    phi = rng.uniform(-np.pi, np.pi, n)
    length = rng.uniform(0.05, 0.2, n)
    poses = pcc.arc_poses(k, phi, length)
    assert poses.shape == (n, 4, 4)
    np.testing.assert_allclose(poses[:, :3, 3], closed_form_tip(k, phi, length), atol=1e-15)
    rot = poses[:, :3, :3]
    eye = np.broadcast_to(np.eye(3), rot.shape)
    np.testing.assert_allclose(rot @ np.swapaxes(rot, 1, 2), eye, atol=1e-14)
    np.testing.assert_array_equal(poses[:, 3], np.broadcast_to([0.0, 0.0, 0.0, 1.0], (n, 4)))
    for i in [0, n // 2, n - 1]:
        np.testing.assert_array_equal(poses[i], pcc.arc_pose(k[i], phi[i], length[i]))


def test_numbers_are_repeated():
    poses = pcc.arc_poses([1.0, 2.0, 3.0], 0.3, 0.1)
    for i, k in enumerate([1.0, 2.0, 3.0]):
        np.testing.assert_array_equal(poses[i], pcc.arc_pose(k, 0.3, 0.1))


@pytest.mark.parametrize("n", [300, 30_000])
def test_the_first_invalid_arc_is_named(n):
    k = np.full(n, 5.0)
    k[n - 50] = np.nan
    k[n - 10] = np.inf
    with pytest.raises(softrod.ParameterError, match=rf"curvature\[{n - 50}\]"):
        pcc.arc_poses(k, 0.1, 0.1)


def test_mismatched_lengths_are_named():
    with pytest.raises(softrod.ParameterError, match=r"plane_angle\.len\(\)"):
        pcc.arc_poses([1.0, 2.0, 3.0], [0.1, 0.2], 0.1)
