"""palc in SUMO (`palc.sumo`): the road from plain XML, the placed scene and its IDM
parameters, the neighbours' gaps corrected by minGap, the learning loop of the
paper's users in SUMO's traffic (seeded, with FCD output), a SUMO that dies mid-run,
and the error when SUMO is missing."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

import palc
from conftest import LEARN_CONFIG

sumo = pytest.importorskip("palc.sumo")
libsumo = pytest.importorskip("libsumo")
sumolib = pytest.importorskip("sumolib")


def config(style: str) -> palc.LearnConfig:
    text = LEARN_CONFIG.read_text()
    return palc.LearnConfig.from_toml_str(text.replace('style = "neutral"', f'style = "{style}"'))


def scene() -> dict:
    idm = {"v0": 17.9, "t": 1.6, "s0": 2.0, "a": 0.73, "b": 1.67, "delta": 4.0}

    def vehicle(id: int, role: str, lane: int, s: float, v: float) -> dict:
        return {"id": id, "role": role, "lane": lane, "s": s, "l": lane * 3.5, "v": v,
                "length": 5.0, "width": 1.8, "idm": dict(idm, t=1.2 + 0.1 * id)}

    return {"dt": 0.1, "lanes": 2, "lane_width": 3.5, "vehicles": [
        vehicle(0, "ego", 0, 20.0, 20.1), vehicle(1, "preceding", 0, 80.0, 17.9),
        vehicle(2, "adjacent", 1, 45.0, 17.9), vehicle(3, "other", 1, 5.0, 17.9)]}


def test_the_road_is_two_lanes_built_from_plain_xml(tmp_path: Path) -> None:
    net = sumolib.net.readNet(str(sumo.netconvert_road(tmp_path, 2, 3.5)))
    lanes = net.getEdge(sumo.EDGE).getLanes()
    assert len(lanes) == 2
    assert [lane.getWidth() for lane in lanes] == pytest.approx([3.5, 3.5])
    assert lanes[0].getShape()[0][1] < lanes[1].getShape()[0][1]  # lane 0 on the right


def test_the_scene_is_placed_with_its_idm_and_the_gaps_are_bumper_to_bumper(tmp_path: Path) -> None:
    with sumo.SumoWorld(out=tmp_path) as world:
        placed = scene()
        world.place(placed)
        for v in placed["vehicles"][1:]:
            id = str(v["id"])
            assert libsumo.vehicle.getLanePosition(id) - sumo.OFFSET_M == pytest.approx(v["s"])
            assert libsumo.vehicle.getLaneIndex(id) == v["lane"]
            assert libsumo.vehicle.getTau(id) == pytest.approx(v["idm"]["t"])
            assert libsumo.vehicle.getMinGap(id) == pytest.approx(v["idm"]["s0"])
            assert libsumo.vehicle.getAccel(id) == pytest.approx(v["idm"]["a"])
            assert libsumo.vehicle.getDecel(id) == pytest.approx(v["idm"]["b"])
        reports = {r["id"]: r for r in world.step({"s": 22.01, "l": 0.0, "v": 20.1, "heading": 0.0})}
        gaps = world.neighbours()
        # Net gaps, from the reported positions: the front bumper minus the other's length.
        assert gaps["leader"][0] == "1"
        assert gaps["leader"][1] == pytest.approx(reports[1]["s"] - 5.0 - 22.01, abs=1e-6)
        assert gaps["left_leader"][0] == "2"
        assert gaps["left_leader"][1] == pytest.approx(reports[2]["s"] - 5.0 - 22.01, abs=1e-6)
        assert gaps["left_follower"][0] == "3"
        assert gaps["left_follower"][1] == pytest.approx(22.01 - 5.0 - reports[3]["s"], abs=1e-6)
        for id, r in reports.items():
            assert r["l"] == pytest.approx(placed["vehicles"][id]["l"])


@pytest.mark.parametrize("style", ["aggressive", "cautious"])
def test_the_papers_users_are_taught_in_sumo_traffic(style: str, tmp_path: Path) -> None:
    own = palc.learn(config(style))
    runs = []
    for _ in range(2):
        with sumo.SumoWorld(out=tmp_path, seed=3) as world:
            runs.append(palc.learn(config(style), world=world))
    there = runs[0]
    assert there.outcome == "personalized"
    assert abs(there.counted_takeovers - own.counted_takeovers) <= 0.5
    assert all(not r["safety"]["collision"] for r in there.records)
    # Seeded: the same traffic, so the same gaps to it.
    assert [r["safety"] for r in runs[1].records] == [r["safety"] for r in there.records]
    fcd = sorted(tmp_path.glob("fcd-*.parquet"))
    assert len(fcd) == there.lane_changes and all(f.stat().st_size > 0 for f in fcd)


class Dies(sumo.SumoWorld):
    """SUMO's simulation ends under the bridge at the fifth step."""

    def step(self, ego):  # type: ignore[no-untyped-def]
        if self.lane_change_steps == 5:
            libsumo.close()
        return super().step(ego)


def test_a_sumo_that_dies_mid_run_ends_it_with_an_error(tmp_path: Path) -> None:
    world = Dies(out=tmp_path)
    with pytest.raises(palc.SimulatorError, match="step 5") as raised:
        palc.learn(config("neutral"), world=world)
    assert "fcd-000.parquet" in str(raised.value)
    world._running = False


def test_a_missing_sumo_names_the_package_and_the_extra() -> None:
    code = (
        "import sys; sys.modules['libsumo'] = None\n"
        "import palc\n"
        "try:\n"
        "    import palc.sumo\n"
        "except palc.SimulatorMissing as e:\n"
        "    print(e.package, e.extra, e)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.startswith("libsumo sumo")
    assert "pip install palc[sumo]" in out


class Neutral(palc.User):
    """The paper's neutral driver written in Python."""

    name = "neutral in Python"

    def nominal(self, scene: palc.Scene) -> palc.LaneChange:
        start = int((scene["situations"]["time_headway_s"] <= 1.23).argmax())
        return {"start_s": start * scene["dt"], "duration_s": 2.1}


def test_a_python_driver_is_taught_in_closed_loop_among_sumo_traffic(tmp_path: Path) -> None:
    text = LEARN_CONFIG.read_text().replace(
        "enabled = false                    # off: one plan", "enabled = true # one plan"
    )
    closed = palc.LearnConfig.from_toml_str(text)
    own = palc.learn(closed, user=Neutral())
    with sumo.SumoWorld(out=tmp_path, fcd=False) as world:
        there = palc.learn(closed, user=Neutral(), world=world)
    assert there.outcome == own.outcome == "personalized"
    assert there.counted_takeovers == own.counted_takeovers
    # Re-planned every step: the rehearsal and the drive each place the scene.
    assert world.placements == 2 * there.lane_changes
    assert all(r["closed_loop"]["replans"] > 0 for r in there.records)
