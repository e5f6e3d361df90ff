"""The .cfg side of live parameters: a dynamic_reconfigure type made from config dataclass fields. No rospy.

A package's cfg/NAME.cfg (run by catkin at build time) calls `generate` with
the fields its server serves (a tb3_common.params dataclass's live fields,
parameter(..., live=True)), so that the server's parameters are the config's,
with their defaults and docs: one source. No bounds: dynamic_reconfigure
would clamp an out-of-range value without a word; the node checks a change as
it checks a start-up value and refuses a bad one saying why.

A .cfg runs before any devel space serves the packages it imports, so it puts
their src/ folders on sys.path itself: its own, and its siblings' (in a
workspace the packages sit side by side; here in packages/).
"""
import dataclasses

from .params import kind_of


def live_fields(config_class):
    """The fields of a config dataclass marked live (parameter(..., live=True))."""
    return [field for field in dataclasses.fields(config_class) if field.metadata.get('live')]


def generate(package, node_name, name, fields, default_of=None):
    """Generates `<name>Config` of `package` for the node `node_name` from dataclass `fields` (each field's
    default, or `default_of(field)`); the .cfg's exit status."""
    from dynamic_reconfigure.parameter_generator_catkin import ParameterGenerator, bool_t, double_t, int_t, str_t
    kinds = {float: double_t, int: int_t, bool: bool_t, str: str_t}
    generator = ParameterGenerator()
    for field in fields:
        unit = field.metadata.get('unit')
        doc = field.metadata.get('doc', '')
        doc += ' (%s)' % unit if unit and unit not in doc else ''
        default = field.default if default_of is None else default_of(field)
        generator.add(field.name, kinds[kind_of(field)[0]], 0, doc, default)
    return generator.generate(package, node_name, name)

