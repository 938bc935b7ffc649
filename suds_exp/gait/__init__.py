"""Gaits: read any gait, predict its motion from a learned map, see the learned
connection, design a better gait and verify it on the simulator."""
