"""fake_localization: the ground truth as a localization would publish it (see node)."""
import tb3_common  # noqa: F401 (first, before numpy: one BLAS thread, see its docstring)
