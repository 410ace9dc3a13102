"""examples/train/swap_scripted.py: the swap is reachable in Swap-v0's 5 s, and only by
leaving the straight line (docs/training.md "Swap": 100 held-out worlds, 0 / 100 / 100 %),
and holding short of the middle earns far less than swapping."""

from __future__ import annotations

from swap_scripted import Strategy, run

EPISODES = 5  # held-out seeds 1,000,000 … 1,000,004 (a second of CPU for all three)


def test_straight_to_the_target_always_collides_in_the_middle():
    r = run(Strategy("straight"), EPISODES)
    assert (r["success"], r["collision"]) == (0, EPISODES)
    assert max(r["returns"]) < 20  # measured 9.1 on average over 100 worlds


def test_a_roundabout_one_shared_rule_swaps_every_world():
    r = run(Strategy("roundabout", offset=1.0), EPISODES)
    assert r["success"] == EPISODES
    assert min(r["returns"]) > 100  # measured 125.6 on average over 100 worlds


def test_altitude_layers_swap_every_world_but_need_more_than_two_hulls():
    assert run(Strategy("altitude", layer=0.6), EPISODES)["success"] == EPISODES
    # 0.3 m between layers is two 0.15 m hulls touching: every world collides.
    assert run(Strategy("altitude", layer=0.3), EPISODES)["collision"] == EPISODES


def test_holding_short_of_the_middle_is_safe_but_earns_little():
    r = run(Strategy("hold", stop=0.4), EPISODES)
    assert (r["not_arrived"], r["collision"]) == (EPISODES, 0)
    assert max(r["returns"]) < 40  # measured 28.6 on average over 100 worlds (1.0 m: 17.8)
