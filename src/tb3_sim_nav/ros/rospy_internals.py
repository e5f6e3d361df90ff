"""Every use of rospy's internals, in one place.

rospy (Debian's 1.15) offers no public way to do these; each function says
what it relies on, so that a change of rospy shows up here and nowhere else.
"""
import rospy


def stop_following_clock():
    """Under sim time rospy subscribes every node to /clock, this one too: here
    that would send every tick through a socket back to where it came from.
    Drop that subscription (True); the step loop then sets rospy's time.
    Relies on rospy.impl.simtime._clock_sub."""
    from rospy.impl import simtime
    if rospy.rostime.is_wallclock() or simtime._clock_sub is None:
        return False
    simtime._clock_sub.unregister()
    return True


def set_time(stamp):
    """rospy's notion of now, for a node that does not follow /clock itself."""
    rospy.rostime._set_rostime(stamp)


def subscriber_connections(subscriber):
    """The current list of a Subscriber's connections (rospy replaces the list
    whenever one comes or goes), each with `header` (None until its handshake
    is done), `callerid_pub`, `endpoint_id` (the publisher's XML-RPC URI) and
    `socket`. Relies on Subscriber.impl.connections."""
    impl = subscriber.impl
    return impl.connections if impl is not None else ()


def wrap_connections(publisher, wrap):
    """Have every subscriber connection of `publisher`, present and future, go
    through `wrap(connection)`: an object that behaves as rospy's transport
    (write_data, fileno, close... as rospy's own QueuedConnection does).
    Relies on _PublisherImpl.add_connection, .connections, .c_lock and .publock."""
    impl = publisher.impl
    add_connection = impl.add_connection

    def add_wrapped(connection):
        return add_connection(wrap(connection))
    impl.add_connection = add_wrapped
    # A subscriber may have connected between registration and now.
    with impl.publock, impl.c_lock:
        impl.connections = [wrap(connection) for connection in impl.connections]


def publisher_connections(publisher):
    """The current list of a Publisher's subscriber connections (rospy replaces the
    list whenever one comes or goes), each with `endpoint_id` (the subscriber's
    caller id) and `socket`. Relies on _PublisherImpl.connections."""
    impl = publisher.impl
    return impl.connections if impl is not None else ()


def ignore_own_publications(subscriber):
    """Never connect `subscriber` to this node's own publisher of its topic
    (rospy would, and send each of our messages through a socket back to us).
    Relies on rospy asking Subscriber.impl.has_connection(publisher URI)
    before it connects (masterslave._connect_topic)."""
    impl, own = subscriber.impl, rospy.core.get_node_uri()
    has_connection = impl.has_connection
    impl.has_connection = lambda uri: uri == own or has_connection(uri)
    # rospy may have connected already, between registering and here: close that
    # connection (Subscriber.impl.connections, endpoint_id the publisher's URI).
    for connection in list(impl.connections):
        if connection.endpoint_id == own:
            impl.remove_connection(connection)
            connection.close()


def caller_id(message):
    """The node that published a received message. Relies on rospy's
    _connection_header, which it sets on every message it delivers."""
    return message._connection_header.get('callerid', '')


def register_again(master, parameters):
    """Register this node's publications, subscriptions and services with a
    master that was restarted (it knows no node), and set `parameters` (a
    dict) again. Relies on rospy.impl.registration's managers."""
    from rospy.impl import registration
    topics, services = registration.get_topic_manager(), registration.get_service_manager()
    uri = rospy.core.get_node_uri()
    for name, value in list(parameters.items()):
        master.setParam(name, value)
    managers = [listener for listener in registration.get_registration_listeners().listeners
                if isinstance(listener, registration.RegManager)]
    for topic, message_type in topics.get_publications():
        master.registerPublisher(topic, message_type, uri)
    for topic, message_type in topics.get_subscriptions():
        publishers = master.registerSubscriber(topic, message_type, uri)
        for manager in managers:
            manager.publisher_update(topic, publishers)
    for service, service_uri in services.get_services():
        master.registerService(service, service_uri, uri)
