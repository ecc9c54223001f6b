"""The S3C2440 program: vision, ranging, planning, control, kinematics and the task."""
