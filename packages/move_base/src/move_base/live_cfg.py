"""The .cfg side of move_base's live parameters: a dynamic_reconfigure type made from a config's live fields.

cfg/DWAPlanner.cfg, cfg/BaseLocalPlanner.cfg and cfg/InflationPlugin.cfg
call `generate` at build time, so the servers' parameters are the configs'
live fields (parameter(..., live=True)) with their defaults and docs: one
source. No bounds: the node checks a change as it checks a start-up value
and refuses a bad one saying why (move_base.live).
"""
import dataclasses

from tb3_common.params import kind_of


def generate(package, name, config_class):
    """Generates `<name>Config` of `package` from the live fields of `config_class`; the .cfg's exit status."""
    from dynamic_reconfigure.parameter_generator_catkin import ParameterGenerator, bool_t, double_t, int_t, str_t
    kinds = {float: double_t, int: int_t, bool: bool_t, str: str_t}
    generator = ParameterGenerator()
    for field in dataclasses.fields(config_class):
        if field.metadata.get('live'):
            unit = field.metadata.get('unit')
            doc = field.metadata.get('doc', '') + (' (%s)' % unit if unit and unit not in field.metadata['doc'] else '')
            generator.add(field.name, kinds[kind_of(field)[0]], 0, doc, field.default)
    return generator.generate(package, package, name)
