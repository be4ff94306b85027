"""Command controllers: forward/group commands, single joints, GPIO and the PID controller."""
