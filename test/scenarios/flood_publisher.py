"""Publish std_msgs/Float64 on a topic at a fixed rate for a while; print how many went out.

Run as its own process by test_flood_and_soak.py (the flood must come from
another process, as it would from a misbehaving client):

    python flood_publisher.py TOPIC RATE_HZ SECONDS

Messages go out in bursts paced by the monotonic clock, so the average rate
holds even though one publish is not scheduled exactly.  The last line on
stdout is ``sent <count> from <start> to <end>``, both ``time.monotonic()``
(the system's monotonic clock, the same in every process on the machine).
"""

from __future__ import annotations

import math
import sys
import time

import rclpy
from rclpy.node import Node
from std_msgs.msg import Float64

DISCOVERY_BUDGET_S = 30.0


def flood(topic: str, rate_hz: float, seconds: float) -> tuple[int, float, float]:
    """Publish on ``topic`` at ``rate_hz`` for ``seconds``; return (count, start, end)."""
    rclpy.init()
    node = Node('flood_publisher')
    publisher = node.create_publisher(Float64, topic, 10)
    deadline = time.monotonic() + DISCOVERY_BUDGET_S
    while publisher.get_subscription_count() == 0 and time.monotonic() < deadline:
        time.sleep(0.01)
    message = Float64()
    sent = 0
    start = time.monotonic()
    now = start
    while now - start < seconds:
        due = math.floor((now - start) * rate_hz)
        while sent < due:
            # Alternate between two targets, and now and then a NaN, as a bad client might.
            message.data = math.nan if sent % 1000 == 0 else (0.5 if sent % 2 else -0.5)
            publisher.publish(message)
            sent += 1
        now = time.monotonic()
    node.destroy_node()
    rclpy.try_shutdown()
    return sent, start, now


if __name__ == '__main__':
    count, start, end = flood(sys.argv[1], float(sys.argv[2]), float(sys.argv[3]))
    print(f'sent {count} from {start:.6f} to {end:.6f}', flush=True)
