"""Where to put the robot: base placements searched for the one that serves a task region most repeatably."""
