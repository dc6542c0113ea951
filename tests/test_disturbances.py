"""The disturbance sets W of Assumption 1: membership up to rounding, at any scale."""
import numpy as np

import orrc


def test_ball_and_box_membership_is_relative_to_the_set_scale():
    for s in (1e-12, 1.0, 1e12):           # the same sets in other units
        ball, box = orrc.disturbances.Ball(s, 2), orrc.disturbances.Box(-s, 2 * s, n=2)
        assert ball.contains(ball.sample(50, seed=0)) and box.contains(box.sample(50, seed=0))
        assert ball.contains([[s, 0.0]]) and box.contains([[-s, 2 * s]])        # the boundary
        assert not ball.contains([[s * (1 + 1e-6), 0.0]])                      # just outside
        assert not box.contains([[-s * (1 + 1e-6), 0.0]]) and not box.contains([[0.0, 2 * s * (1 + 1e-6)]])
    assert orrc.disturbances.Box(0.0, 0.0, n=1).contains(np.zeros((3, 1)))
    assert not orrc.disturbances.Box(0.0, 0.0, n=1).contains([[1e-300]])
