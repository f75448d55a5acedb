"""The building as it is, which differs from its plan: furniture, people, closed doors, walls
displaced. The robot knows only the plan; the simulated LiDAR and collision check see this."""
