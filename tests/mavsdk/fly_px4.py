#!/usr/bin/env python3
"""MAVSDK (asyncio), the ground station library built around PX4, flies a drone of
`aviary vehicles --autopilot px4`.

Usage: fly_px4.py AVIARY_BINARY WORLD_FILE

Starts `aviary vehicles --world WORLD --listen tcp:127.0.0.1:0 --speed 5 --autopilot px4`,
reads the port from its first line, then with MAVSDK over tcpout://:
- finds system 1 and that it is a PX4 autopilot; waits until the health says global
  position, home position and armable;
- sets the take-off altitude (MIS_TAKEOFF_ALT) to 10 m, arms, takes off: the flight mode
  is HOLD once at 10 m (PX4 hands a finished take-off over to Hold);
- goto_location 30 m north at the same altitude above sea level: there within 2 m;
- do_orbit of 15 m around that point: the drone circles it (15 m ± 2 m from the centre,
  over more than a quarter of the circle); hold;
- uploads a mission of three waypoints (40 m east, 40 m east and 40 m north at 15 m,
  back over home at 10 m), starts it and waits until MAVSDK says it is finished: each
  waypoint was passed within 2 m, and the mode is HOLD again;
- return_to_launch: lands within 2 m of home and disarms by itself (PX4's auto-disarm);
- arms, takes off again, lands with land() where it is, and disarms by itself.
MAVSDK's own warnings and errors fail the flight. Every wait has a limit; exit 0 on
success, 1 with the step that failed.
"""
import asyncio
import math
import subprocess
import sys
import time

import mavsdk
from mavsdk import LogLevel, log_subscribe
from mavsdk.asyncio import ComponentType, Configuration, Mavsdk
from mavsdk.autopilot import Autopilot
from mavsdk.asyncio.plugins.action import ActionAsync
from mavsdk.asyncio.plugins.mission import MissionAsync
from mavsdk.asyncio.plugins.telemetry import TelemetryAsync
from mavsdk.plugins.action import OrbitYawBehavior
from mavsdk.plugins.mission import MissionItem, MissionPlan
from mavsdk.plugins.telemetry import FlightMode

SPEED = 5
EARTH_RADIUS = 6_371_000.0
SYSTEM = 1

# What MAVSDK logged at WARN or above, as (level, message).
complaints = []


def log(level, message, _file, _line):
    if level >= LogLevel.WARN:
        complaints.append((level.name, message))
        print(f"mavsdk_px4: MAVSDK {level.name}: {message}")
    return True


class Failed(Exception):
    pass


async def until(limit, step, check, every=0.1):
    deadline = time.monotonic() + limit
    while time.monotonic() < deadline:
        result = await check()
        if result:
            return result
        await asyncio.sleep(every)
    raise Failed(f"{step} (waited {limit} s)")


def offset(lat, lon, north, east):
    """The point `north` and `east` metres from (lat, lon)."""
    return (lat + math.degrees(north / EARTH_RADIUS),
            lon + math.degrees(east / (EARTH_RADIUS * math.cos(math.radians(lat)))))


def apart(p, lat, lon):
    """Metres over the ground from position `p` to (lat, lon)."""
    north = math.radians(p.latitude_deg - lat) * EARTH_RADIUS
    east = math.radians(p.longitude_deg - lon) * EARTH_RADIUS * math.cos(math.radians(lat))
    return math.hypot(north, east)


async def fly(address):
    async with Mavsdk(Configuration.create_with_component_type(ComponentType.GROUND_STATION)) as sdk:
        await sdk.add_any_connection(f"tcpout://{address}")

        async def vehicle():
            for s in await sdk.get_systems():
                if await s.get_system_id() == SYSTEM and await s.has_autopilot():
                    return s
            return None
        drone = await until(15, f"discovering system {SYSTEM}", vehicle)
        kind = await drone.autopilot_type()
        print(f"mavsdk_px4: found system {SYSTEM} ({kind.name})")
        if kind != Autopilot.PX4:
            raise Failed(f"system {SYSTEM} is not a PX4 autopilot: {kind.name}")
        action, telemetry = ActionAsync(drone), TelemetryAsync(drone)
        mission = MissionAsync(drone)

        async def healthy():
            h = await telemetry.health()
            return h.is_global_position_ok and h.is_home_position_ok and h.is_armable
        await until(30, "health: global position, home position, armable", healthy)
        home = await telemetry.home()
        print(f"mavsdk_px4: healthy; home {home.latitude_deg:.7f} {home.longitude_deg:.7f} "
              f"{home.absolute_altitude_m:.1f} m")

        async def mode_is(mode):
            async def check():
                return await telemetry.flight_mode() == mode
            return check

        # MIS_TAKEOFF_ALT first: PX4 disarms 10 s (2 s here) after arming without a take-off.
        await action.set_takeoff_altitude(10.0)
        if abs(await action.get_takeoff_altitude() - 10.0) > 0.01:
            raise Failed("MIS_TAKEOFF_ALT did not become 10 m")
        await action.arm()
        await until(5, "armed", telemetry.armed)
        await action.takeoff()

        async def up():
            return (await telemetry.position()).relative_altitude_m >= 9.9
        await until(30, "climbing to 10 m", up)
        await until(5, "HOLD after the take-off", await mode_is(FlightMode.HOLD))
        here = await telemetry.position()
        print(f"mavsdk_px4: at {here.relative_altitude_m:.1f} m, in HOLD")

        lat, lon = offset(here.latitude_deg, here.longitude_deg, 30.0, 0.0)
        amsl = here.absolute_altitude_m
        await action.goto_location(lat, lon, amsl, 0.0)

        async def arrived():
            p = await telemetry.position()
            return apart(p, lat, lon) < 2.0 and abs(p.absolute_altitude_m - amsl) < 1.0
        await until(30, f"goto_location 30 m north at {amsl:.1f} m AMSL", arrived)
        print(f"mavsdk_px4: arrived 30 m north at {amsl:.1f} m above sea level")

        radius = 15.0
        await action.do_orbit(radius, 3.0, OrbitYawBehavior.HOLD_FRONT_TO_CIRCLE_CENTER,
                              lat, lon, amsl)
        bearings = []

        async def circling():
            p = await telemetry.position()
            if abs(apart(p, lat, lon) - radius) < 2.0:
                north = math.radians(p.latitude_deg - lat) * EARTH_RADIUS
                east = math.radians(p.longitude_deg - lon) * EARTH_RADIUS * math.cos(math.radians(lat))
                bearings.append(math.atan2(east, north))
            if len(bearings) < 2:
                return False
            turned = sum(abs(math.remainder(b - a, math.tau)) for a, b in zip(bearings, bearings[1:]))
            return turned > math.pi / 2
        await until(60, f"orbiting {radius:g} m around the point", circling)
        print(f"mavsdk_px4: orbited {radius:g} m around the point ({len(bearings)} samples on the circle)")
        await action.hold()
        await until(5, "HOLD after the orbit", await mode_is(FlightMode.HOLD))

        points = [
            offset(home.latitude_deg, home.longitude_deg, 0.0, 40.0) + (15.0,),
            offset(home.latitude_deg, home.longitude_deg, 40.0, 40.0) + (15.0,),
            (home.latitude_deg, home.longitude_deg, 10.0),
        ]
        plan = MissionPlan([
            MissionItem(latitude_deg=p[0], longitude_deg=p[1], relative_altitude_m=p[2],
                        speed_m_s=5.0, is_fly_through=False)
            for p in points
        ])
        await mission.upload_mission(plan)
        print(f"mavsdk_px4: mission of {len(points)} waypoints uploaded")
        await mission.start_mission()
        nearest = [math.inf] * len(points)

        async def finished():
            p = await telemetry.position()
            for k, (plat, plon, rel) in enumerate(points):
                d = math.hypot(apart(p, plat, plon), p.relative_altitude_m - rel)
                nearest[k] = min(nearest[k], d)
            return await mission.is_mission_finished()
        await until(90, "the mission finished", finished)
        if max(nearest) > 2.0:
            raise Failed(f"a waypoint was missed: nearest passes {nearest}")
        await until(5, "HOLD after the mission", await mode_is(FlightMode.HOLD))
        print("mavsdk_px4: mission finished; each waypoint passed within "
              f"{max(nearest):.2f} m; HOLD")

        await action.return_to_launch()
        await until(5, "RETURN_TO_LAUNCH mode", await mode_is(FlightMode.RETURN_TO_LAUNCH))

        async def disarmed():
            return not await telemetry.armed()
        await until(90, "returning, landing and disarming", disarmed)
        p = await telemetry.position()
        if apart(p, home.latitude_deg, home.longitude_deg) > 2.0 or p.relative_altitude_m > 0.5:
            raise Failed(f"landed away from home: {apart(p, home.latitude_deg, home.longitude_deg):.1f} m, "
                         f"{p.relative_altitude_m:.1f} m up")
        print("mavsdk_px4: returned, landed at home and disarmed")

        await action.arm()
        await until(5, "armed again", telemetry.armed)
        await action.takeoff()
        await until(30, "climbing to 10 m again", up)
        await action.land()
        await until(5, "LAND mode", await mode_is(FlightMode.LAND))
        await until(60, "landing and disarming", disarmed)
        p = await telemetry.position()
        if p.relative_altitude_m > 0.5:
            raise Failed(f"disarmed {p.relative_altitude_m:.1f} m up")
        print("mavsdk_px4: took off, landed where it was and disarmed")


def main():
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    aviary, world = sys.argv[1], sys.argv[2]
    started = time.monotonic()
    log_subscribe(log)
    print(f"mavsdk_px4: mavsdk {mavsdk.__version__}")
    server = subprocess.Popen(
        [aviary, "vehicles", "--world", world, "--listen", "tcp:127.0.0.1:0",
         "--speed", str(SPEED), "--autopilot", "px4"],
        stdout=subprocess.PIPE, text=True,
    )
    try:
        first = server.stdout.readline().strip()
        if "listening on tcp:" not in first:
            raise Failed(f"aviary vehicles did not start: {first!r}")
        print(f"mavsdk_px4: {first}")
        asyncio.run(asyncio.wait_for(fly(first.split("listening on tcp:")[1]), 300))
        if complaints:
            raise Failed(f"MAVSDK complained {len(complaints)} times, first: {complaints[0]}")
    except (Failed, mavsdk.MavsdkError, asyncio.TimeoutError, Exception) as e:
        print(f"mavsdk_px4: FAILED: {type(e).__name__}: {e}", file=sys.stderr)
        sys.exit(1)
    finally:
        server.terminate()
        server.wait(timeout=10)
    print(f"mavsdk_px4: OK in {time.monotonic() - started:.0f} s")


if __name__ == "__main__":
    main()
