"""Stage 3: the world. Scene (obstacles posed in the robot base frame), collision and clearance
queries, the allowed-collision proof, and the motion check shared by the planner and the verifier."""
