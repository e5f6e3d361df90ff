"""multirobot_map_merge: its parameters (config), robot discovery (discovery), the merge (merge), the node."""
import tb3_common  # noqa: F401 (first, before numpy: one BLAS thread, see its docstring)
