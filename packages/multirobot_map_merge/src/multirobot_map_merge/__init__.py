"""multirobot_map_merge: its parameters (config), robot discovery (discovery), the merge (merge), the node."""
