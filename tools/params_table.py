"""Prints the README's table of the simulator's parameters, from params.py."""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'src'))
from tb3_sim_nav.params import FROM_MODEL, FROM_PROFILE, PARAMETERS, PROFILES  # noqa: E402


def shown(value):
    if isinstance(value, bool):
        return 'true' if value else 'false'
    return '`%s`' % value if isinstance(value, str) else repr(value)


def main():
    print('| parameter | default | unit | meaning |')
    print('|---|---|---|---|')
    for parameter in PARAMETERS:
        if parameter.origin == FROM_MODEL:
            default = "the model's"
        elif parameter.origin == FROM_PROFILE:
            default = ', '.join('%s: %s' % (profile, shown(PROFILES[profile][parameter.name]))
                                for profile in sorted(PROFILES))
        elif parameter.default == ():
            default = '(none)'
        else:
            default = shown(parameter.default)
        live = ' (live: `dynparam set`)' if parameter.live else ''
        print('| `~%s` | %s | %s | %s%s |' % (parameter.name, default, parameter.unit, parameter.doc, live))


if __name__ == '__main__':
    main()
