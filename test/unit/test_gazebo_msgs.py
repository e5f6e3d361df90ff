"""Our gazebo_msgs speaks Gazebo's wire format: the md5sum of every message and
service it generates equals the one genmsg computes from Gazebo's own Noetic
definitions (test/data/gazebo_msgs_noetic, see SOURCE there). A script written
for Gazebo connects to ours only if these agree."""
import importlib

import genmsg
import genmsg.msg_loader
import pytest

from conftest import REPO

OURS = REPO / 'packages' / 'gazebo_msgs'
GAZEBOS = REPO / 'test' / 'data' / 'gazebo_msgs_noetic'
# Gazebo's definitions and the std_msgs/geometry_msgs ones Debian installs
# (ros-std-msgs, ros-geometry-msgs).
SEARCH_PATH = {
    'gazebo_msgs': [str(GAZEBOS / 'msg')],
    'std_msgs': ['/usr/share/std_msgs/msg'],
    'geometry_msgs': ['/usr/share/geometry_msgs/msg'],
}

# md5sums published apart from Gazebo's sources and from ours: the headers
# rosserial generated from an installed gazebo_msgs, in the repository
# stanfordroboticsclub/StanfordQuadruped, dingo_nano/libraries/ros_lib/gazebo_msgs/
# (commit 4d1acb72bc2665ff70e1403e288df10dde7c3d0e).
PUBLISHED = {
    'gazebo_msgs/ModelState': '9330fd35f2fcd82d457e54bd54e10593',
    'gazebo_msgs/ModelStates': '48c080191eb15c41858319b4d8a609c2',
    'gazebo_msgs/LinkState': '0818ebbf28ce3a08d48ab1eaa7309ebe',
    'gazebo_msgs/ODEPhysics': '667d56ddbd547918c32d1934503dc335',
    'gazebo_msgs/GetModelStateRequest': '19d412713cefe4a67437e17a951e759e',
    'gazebo_msgs/GetModelStateResponse': 'ccd51739bb00f0141629e87b792e92b9',
    'gazebo_msgs/SetModelStateRequest': 'cb042b0e91880f4661b29ea5b6234350',
}


def names(folder, kind):
    return sorted(path.stem for path in (folder / kind).glob('*.' + kind))


def gazebo_md5sums():
    """{type name: md5sum} from Gazebo's definitions, for each message, each
    service, and each service's Request and Response."""
    context = genmsg.MsgContext.create_default()
    md5sums = {}
    for name in names(GAZEBOS, 'msg'):
        spec = genmsg.msg_loader.load_msg_by_type(context, 'gazebo_msgs/' + name, SEARCH_PATH)
        genmsg.msg_loader.load_depends(context, spec, SEARCH_PATH)
        md5sums['gazebo_msgs/' + name] = genmsg.compute_md5(context, spec)
    for name in names(GAZEBOS, 'srv'):
        spec = genmsg.msg_loader.load_srv_from_file(
            context, str(GAZEBOS / 'srv' / (name + '.srv')), 'gazebo_msgs/' + name)
        genmsg.msg_loader.load_depends(context, spec, SEARCH_PATH)
        md5sums['gazebo_msgs/' + name] = genmsg.compute_md5(context, spec)
        for part in ('request', 'response'):
            md5sums[getattr(spec, part).full_name] = genmsg.compute_md5(context, getattr(spec, part))
    return md5sums


GAZEBO_MD5SUMS = gazebo_md5sums()


def generated_classes():
    """Our generated Python classes, each service with its Request and Response."""
    for name in names(OURS, 'msg'):
        yield getattr(importlib.import_module('gazebo_msgs.msg'), name)
    for name in names(OURS, 'srv'):
        service = getattr(importlib.import_module('gazebo_msgs.srv'), name)
        yield from (service, service._request_class, service._response_class)


def test_we_define_exactly_the_types_kept_from_gazebo():
    for kind in ('msg', 'srv'):
        assert names(OURS, kind) == names(GAZEBOS, kind)


def test_the_brief_s_types_are_all_there():
    assert {'ModelState', 'ModelStates', 'LinkState', 'LinkStates', 'ODEPhysics'} <= set(
        names(OURS, 'msg'))
    assert {'GetModelState', 'SetModelState', 'SpawnModel', 'DeleteModel', 'GetWorldProperties',
            'GetModelProperties', 'GetPhysicsProperties', 'SetPhysicsProperties',
            'GetLinkState', 'SetLinkState'} <= set(names(OURS, 'srv'))


@pytest.mark.parametrize('generated', list(generated_classes()), ids=lambda cls: cls._type)
def test_md5sum_equals_gazebo_s(generated):
    assert generated._md5sum == GAZEBO_MD5SUMS[generated._type]


@pytest.mark.parametrize('type_name', sorted(PUBLISHED))
def test_md5sum_equals_the_published_one(type_name):
    assert GAZEBO_MD5SUMS[type_name] == PUBLISHED[type_name]
    package, name = type_name.split('/')
    for kind in ('msg', 'srv'):
        module = importlib.import_module(package + '.' + kind)
        if hasattr(module, name):
            assert getattr(module, name)._md5sum == PUBLISHED[type_name]
            return
    pytest.fail(type_name + ' is not generated')
