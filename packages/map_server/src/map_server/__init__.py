"""The ROS node(s) of the package map_server, over tb3_navigation's cores."""
import tb3_common  # noqa: F401 (first, before numpy: one BLAS thread, see its docstring)
