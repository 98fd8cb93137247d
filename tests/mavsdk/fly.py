#!/usr/bin/env python3
"""An independent ground station library (MAVSDK, asyncio) flies a drone of `aviary vehicles`.

Usage: fly.py AVIARY_BINARY WORLD_FILE

Starts `aviary vehicles --world WORLD --listen tcp:127.0.0.1:0 --speed 5`, reads the
port from its first line, then with MAVSDK: connects (tcpout://), waits until the
health says global position, home position and armable, arms, takes off, flies with
goto_location to a point 30 m north of home at the same altitude above sea level, checks
it arrives within 2 m, lands and waits for the disarm. MAVSDK's own warnings and errors
fail the flight. Every wait has a limit; exit 0 on success, 1 with the step that failed.
"""
import asyncio
import math
import subprocess
import sys
import time

import mavsdk
from mavsdk import LogLevel, log_subscribe
from mavsdk.asyncio import ComponentType, Configuration, Mavsdk
from mavsdk.asyncio.plugins.action import ActionAsync
from mavsdk.asyncio.plugins.telemetry import TelemetryAsync

SPEED = 5
NORTH = 30.0
EARTH_RADIUS = 6_371_000.0
SYSTEM = 1

# What MAVSDK logged at WARN or above, as (level, message).
complaints = []


def log(level, message, _file, _line):
    if level >= LogLevel.WARN:
        complaints.append((level.name, message))
        print(f"mavsdk_fly: MAVSDK {level.name}: {message}")
    return True


class Failed(Exception):
    pass


async def until(limit, step, check, every=0.2):
    deadline = time.monotonic() + limit
    while time.monotonic() < deadline:
        result = await check()
        if result:
            return result
        await asyncio.sleep(every)
    raise Failed(f"{step} (waited {limit} s)")


async def fly(address):
    async with Mavsdk(Configuration.create_with_component_type(ComponentType.GROUND_STATION)) as sdk:
        await sdk.add_any_connection(f"tcpout://{address}")

        async def vehicle():
            for s in await sdk.get_systems():
                if await s.get_system_id() == SYSTEM and await s.has_autopilot():
                    return s
            return None
        drone = await until(15, f"discovering system {SYSTEM}", vehicle)
        print(f"mavsdk_fly: found system {SYSTEM} ({await drone.autopilot_type()})")
        action, telemetry = ActionAsync(drone), TelemetryAsync(drone)

        async def healthy():
            h = await telemetry.health()
            return h.is_global_position_ok and h.is_home_position_ok and h.is_armable
        await until(30, "health: global position, home position, armable", healthy)
        home = await telemetry.home()
        print(f"mavsdk_fly: healthy; home {home.latitude_deg:.7f} {home.longitude_deg:.7f} "
              f"{home.absolute_altitude_m:.1f} m")

        await action.arm()
        await until(5, "armed", telemetry.armed)
        print("mavsdk_fly: armed")
        await action.set_takeoff_altitude(10.0)
        await action.takeoff()

        async def up():
            return (await telemetry.position()).relative_altitude_m >= 9.9
        await until(30, "climbing to 10 m", up)
        here = await telemetry.position()
        print(f"mavsdk_fly: at {here.relative_altitude_m:.1f} m")

        lat = here.latitude_deg + math.degrees(NORTH / EARTH_RADIUS)
        lon = here.longitude_deg
        amsl = here.absolute_altitude_m
        await action.goto_location(lat, lon, amsl, 0.0)

        async def arrived():
            p = await telemetry.position()
            north = math.radians(p.latitude_deg - lat) * EARTH_RADIUS
            east = math.radians(p.longitude_deg - lon) * EARTH_RADIUS * math.cos(math.radians(lat))
            return math.hypot(north, east) < 2.0 and abs(p.absolute_altitude_m - amsl) < 1.0
        await until(30, f"goto_location {NORTH:g} m north at {amsl:.1f} m AMSL", arrived)
        print(f"mavsdk_fly: arrived {NORTH:g} m north at {amsl:.1f} m above sea level")

        await action.land()

        async def disarmed():
            return not await telemetry.armed()
        await until(60, "landing and disarming", disarmed)
        print("mavsdk_fly: landed and disarmed")


def main():
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    aviary, world = sys.argv[1], sys.argv[2]
    started = time.monotonic()
    log_subscribe(log)
    print(f"mavsdk_fly: mavsdk {mavsdk.__version__}")
    server = subprocess.Popen(
        [aviary, "vehicles", "--world", world, "--listen", "tcp:127.0.0.1:0", "--speed", str(SPEED)],
        stdout=subprocess.PIPE, text=True,
    )
    try:
        first = server.stdout.readline().strip()
        if "listening on tcp:" not in first:
            raise Failed(f"aviary vehicles did not start: {first!r}")
        print(f"mavsdk_fly: {first}")
        asyncio.run(asyncio.wait_for(fly(first.split("listening on tcp:")[1]), 150))
        if complaints:
            raise Failed(f"MAVSDK complained {len(complaints)} times, first: {complaints[0]}")
    except (Failed, mavsdk.MavsdkError, asyncio.TimeoutError, Exception) as e:
        print(f"mavsdk_fly: FAILED: {type(e).__name__}: {e}", file=sys.stderr)
        sys.exit(1)
    finally:
        server.terminate()
        server.wait(timeout=10)
    print(f"mavsdk_fly: OK in {time.monotonic() - started:.0f} s")


if __name__ == "__main__":
    main()
