"""fake_localization: the ground truth as a localization would publish it (see node)."""
