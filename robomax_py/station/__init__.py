"""Multi-robot stations (docs/stations.md): spots assigned to robots and sequenced for the makespan,
robot-robot collisions found on a shared clock and resolved by interlocks."""
