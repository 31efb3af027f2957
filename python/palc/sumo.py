"""palc in SUMO: :class:`SumoWorld`, the :class:`palc.World` that lets the learning
loop drive its lane changes among SUMO's traffic, through libsumo::

    import palc
    from palc.sumo import SumoWorld

    with SumoWorld(out="target/sumo", seed=1) as world:
        result = palc.learn(palc.LearnConfig(), world=world)

The road is a two-lane straight edge written as plain node and edge XML and built
by ``netconvert`` (SUMO's binaries come with the ``eclipse-sumo`` wheel). Every lane
change places palc's scene at the trigger as a route file: the background vehicles
follow SUMO's IDM (``carFollowModel="IDM"``) with palc's parameters (``tau`` = T,
``minGap`` = s0, ``accel`` = a, ``decel`` = b, ``delta``, ``maxSpeed`` = v0) and never
change lanes; SUMO runs headless with the step of palc's plan, seeded (``--seed``),
and writes its FCD output (Parquet) per lane change. Each step the ego is moved where
palc drives it with ``moveToXY(..., keepRoute=2)``, which is exact (``changeSublane``
would lag the plan by up to 0.2 m, too close to the 0.3 m takeover threshold), SUMO
advances, and the vehicles are read back. SUMO's positions are front bumpers along
the lane, as palc's ``s``; its lane 0 is the rightmost, as palc's.

A failure of SUMO (an error, a vehicle lost, a closed simulation) raises
:class:`palc.SimulatorError` naming the step and the FCD file written so far; the
run ends with it instead of waiting. eclipse-sumo, libsumo and sumolib are an
optional extra: ``pip install palc[sumo]``; without them, importing this module
raises :class:`palc.SimulatorMissing`.
"""

from __future__ import annotations

import math
import os
import subprocess
import tempfile
import time
from pathlib import Path
from types import TracebackType
from typing import Any, Dict, List, Optional, Tuple, Type, Union
from xml.sax.saxutils import quoteattr

from palc._errors import SimulatorError, SimulatorMissing
from palc._world import Ego, Placement, Report, World

try:
    import sumo as _sumo  # type: ignore[import-untyped]

    os.environ.setdefault("SUMO_HOME", _sumo.SUMO_HOME)
    import libsumo  # type: ignore[import-untyped]
    import sumolib  # type: ignore[import-untyped]  # noqa: F401  (part of the extra: SUMO's own tools)
except ImportError as _missing:  # pragma: no cover - depends on the installation
    _names = {"sumo": "eclipse-sumo", "libsumo": "libsumo", "sumolib": "sumolib"}
    raise SimulatorMissing(_names.get(getattr(_missing, "name", "") or "", "eclipse-sumo"), "sumo") from _missing

__all__ = ["SumoWorld", "netconvert_road"]

#: The road's length (m), far beyond any lane change's reach.
ROAD_LENGTH_M = 5_000.0
#: Where palc's ``s = 0`` is along SUMO's road (m), so that vehicles behind it fit.
OFFSET_M = 1_000.0
#: The edge's identifier.
EDGE = "road"
#: How long ``netconvert`` may take before it counts as hung (s).
NETCONVERT_TIMEOUT_S = 60.0


def netconvert_road(out: Path, lanes: int, lane_width: float) -> Path:
    """Writes a straight road of ``lanes`` lanes ``lane_width`` wide as plain node and
    edge XML in ``out`` and builds ``road.net.xml`` from them with ``netconvert``."""
    out.mkdir(parents=True, exist_ok=True)
    nodes, edges, net = out / "road.nod.xml", out / "road.edg.xml", out / "road.net.xml"
    nodes.write_text(f'<nodes>\n  <node id="start" x="0" y="0"/>\n  <node id="end" x="{ROAD_LENGTH_M}" y="0"/>\n</nodes>\n')
    edges.write_text(
        f'<edges>\n  <edge id="{EDGE}" from="start" to="end" numLanes="{lanes}" speed="60" width="{lane_width}"/>\n</edges>\n'
    )
    binary = Path(_sumo.SUMO_HOME) / "bin" / "netconvert"
    command = [str(binary), "--node-files", str(nodes), "--edge-files", str(edges), "-o", str(net),
               "--no-turnarounds", "true", "--no-warnings", "true"]
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=NETCONVERT_TIMEOUT_S)
    except (OSError, subprocess.TimeoutExpired) as error:
        raise SimulatorError(f"netconvert could not build {net}: {error}") from error
    if done.returncode != 0:
        raise SimulatorError(f"netconvert could not build {net} (exit {done.returncode}): {done.stderr.strip()}")
    return net


def _vehicle_xml(vehicle: Dict[str, Any]) -> Tuple[str, str]:
    """The vType and vehicle elements of one placed vehicle."""
    id, idm = str(vehicle["id"]), vehicle["idm"]
    size = f'length="{vehicle["length"]}" width="{vehicle["width"]}" speedFactor="1" speedDev="0"'
    if vehicle["role"] == "ego":
        vtype = f'<vType id="t{id}" {size} maxSpeed="100" minGap="0"/>'
    else:
        vtype = (f'<vType id="t{id}" {size} carFollowModel="IDM" tau="{idm["t"]}" minGap="{idm["s0"]}" '
                 f'accel="{idm["a"]}" decel="{idm["b"]}" emergencyDecel="9" delta="{idm["delta"]}" '
                 f'maxSpeed="{max(idm["v0"], 0.1)}" lcStrategic="-1" lcCooperative="-1" lcSpeedGain="0" lcKeepRight="0"/>')
    element = (f'<vehicle id={quoteattr(id)} type="t{id}" route="r" depart="0" departLane="{vehicle["lane"]}" '
               f'departPos="{vehicle["s"] + OFFSET_M}" departPosLat="0" departSpeed="{vehicle["v"]}" insertionChecks="none"/>')
    return vtype, element


class SumoWorld(World):
    """SUMO's traffic as the world of palc's learning loop (one per process: libsumo
    runs one simulation). ``out`` holds the road, the route file and the FCD output
    of every lane change (``fcd-NNN.parquet``); a temporary directory by default."""

    name = "sumo"

    def __init__(self, out: Union[str, Path, None] = None, seed: int = 1, fcd: bool = True) -> None:
        self.out = Path(out) if out is not None else Path(tempfile.mkdtemp(prefix="palc-sumo-"))
        self.seed = seed
        self.fcd = fcd
        self.net: Optional[Path] = None
        self.road: Tuple[int, float] = (0, 0.0)
        self.ids: List[str] = []
        self.lane0_y = 0.0
        #: Lane changes placed, and steps driven in all, so far.
        self.placements = 0
        self.steps = 0
        #: Steps driven in the current lane change.
        self.lane_change_steps = 0
        #: Seconds spent moving the ego and reading the vehicles (the bridge), and in SUMO's steps.
        self.bridge_s = 0.0
        self.sumo_s = 0.0
        self.fcd_file: Optional[Path] = None
        self._running = False

    def __enter__(self) -> "SumoWorld":
        return self

    def __exit__(self, kind: Optional[Type[BaseException]], error: Optional[BaseException],
                 trace: Optional[TracebackType]) -> None:
        self.close()

    def _failed(self, what: str, error: BaseException) -> SimulatorError:
        written = f"; its FCD output so far: {self.fcd_file}" if self.fcd_file else ""
        where = f"lane change {self.placements}, step {self.lane_change_steps}"
        return SimulatorError(f"SUMO failed {what} ({where}): {error}{written}")

    def place(self, scene: Placement) -> None:
        road = (int(scene["lanes"]), float(scene["lane_width"]))
        if self.net is None or road != self.road:
            self.net, self.road = netconvert_road(self.out, *road), road
        types, vehicles = [], []
        for vehicle in scene["vehicles"]:
            vtype, element = _vehicle_xml(dict(vehicle))
            types.append(vtype)
            vehicles.append(element)
        routes = self.out / f"lane-change-{self.placements:03d}.rou.xml"
        body = "\n  ".join(types + [f'<route id="r" edges="{EDGE}"/>'] + vehicles)
        routes.write_text(f"<routes>\n  {body}\n</routes>\n")
        self.fcd_file = self.out / f"fcd-{self.placements:03d}.parquet" if self.fcd else None
        args = ["-n", str(self.net), "-r", str(routes), "--step-length", repr(float(scene["dt"])),
                "--seed", str(self.seed), "--no-step-log", "true", "--no-warnings", "true",
                "--collision.action", "warn", "--time-to-teleport", "-1", "--begin", "0"]
        if self.fcd_file is not None:
            args += ["--fcd-output", str(self.fcd_file)]
        try:
            if self._running:
                libsumo.load(args)
            else:
                libsumo.start(["sumo"] + args)
                self._running = True
            # Vehicles departing at 0 enter in the first step, where they were placed.
            libsumo.simulationStep()
            present = set(libsumo.vehicle.getIDList())
            self.ids = [str(v["id"]) for v in scene["vehicles"] if v["role"] != "ego"]
            self.ego = next(str(v["id"]) for v in scene["vehicles"] if v["role"] == "ego")
            lost = [id for id in self.ids + [self.ego] if id not in present]
            if lost:
                raise RuntimeError(f"vehicles {lost} could not be inserted")
            for id in self.ids:
                libsumo.vehicle.setLaneChangeMode(id, 0)
            self.lane0_y = libsumo.lane.getShape(f"{EDGE}_0")[0][1]
        except Exception as error:  # libsumo's TraCIException and FatalTraCIError included
            raise self._failed("placing the scene", error) from error
        self.placements += 1
        self.lane_change_steps = 0

    def step(self, ego: Ego) -> List[Report]:
        lanes, width = self.road
        started = time.perf_counter()
        try:
            lane = min(max(round(ego["l"] / width), 0), lanes - 1)
            angle = 90.0 - math.degrees(ego["heading"])
            libsumo.vehicle.moveToXY(self.ego, EDGE, lane, ego["s"] + OFFSET_M, self.lane0_y + ego["l"], angle,
                                     keepRoute=2)
            moved = time.perf_counter()
            libsumo.simulationStep()
            stepped = time.perf_counter()
            reports: List[Report] = []
            for id in self.ids:
                s = libsumo.vehicle.getLanePosition(id) - OFFSET_M
                l = libsumo.vehicle.getLaneIndex(id) * width + libsumo.vehicle.getLateralLanePosition(id)
                reports.append({"id": int(id), "s": s, "l": l, "v": libsumo.vehicle.getSpeed(id)})
        except Exception as error:
            raise self._failed("stepping", error) from error
        done = time.perf_counter()
        self.bridge_s += (moved - started) + (done - stepped)
        self.sumo_s += stepped - moved
        self.steps += 1
        self.lane_change_steps += 1
        return reports

    def neighbours(self) -> Dict[str, Optional[Tuple[str, float]]]:
        """The ego's neighbours as SUMO sees them: ``leader``, ``left_leader`` and
        ``left_follower``, each ``(id, net gap in m)`` or ``None``. SUMO's gaps leave
        out the follower's ``minGap``; these are bumper to bumper (SUMO's gap plus
        the follower's ``minGap``)."""
        try:
            min_gap = libsumo.vehicle.getMinGap
            leader = libsumo.vehicle.getLeader(self.ego, 200.0)
            found: Dict[str, Optional[Tuple[str, float]]] = {
                "leader": (leader[0], leader[1] + min_gap(self.ego)) if leader and leader[0] else None,
                "left_leader": None,
                "left_follower": None,
            }
            for id, gap in libsumo.vehicle.getLeftLeaders(self.ego):
                found["left_leader"] = (id, gap + min_gap(self.ego))
            for id, gap in libsumo.vehicle.getLeftFollowers(self.ego):
                found["left_follower"] = (id, gap + min_gap(id))
        except Exception as error:
            raise self._failed("reading the neighbours", error) from error
        return found

    def overhead_ms(self) -> float:
        """The bridge's mean time per step (ms): moving the ego and reading the vehicles."""
        return 1e3 * self.bridge_s / max(self.steps, 1)

    def close(self) -> None:
        """Ends the simulation (SUMO writes its outputs)."""
        if self._running:
            self._running = False
            try:
                libsumo.close()
            except Exception:  # pragma: no cover - a simulation that died closes itself
                pass
