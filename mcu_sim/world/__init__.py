"""The plant: pymunk base, arm, actuators, sonars, camera renderer, scenarios and ground truth."""
