"""ROBOTIS' result_graph and action_graph (pyqtgraph and PyQt5, Debian's), and the same graph as a PNG.

result_graph: "Total reward" and "Average max Q-value" per episode, from
`result` (Float32MultiArray [score, max Q]). action_graph: the five actions
as bars (the one taken full), the total reward and the step's reward, from
`get_action` ([action, score, reward]). `write_png` draws the result graph
with matplotlib (no screen needed) from a results CSV.
"""
import sys

from .ending import finish_now

WINDOW_POLL_MS = 50  # the windows look at the node's end flag this often: Ctrl+C ends them within 2 s


def write_png(results, path, title=''):
    """The score and the average max Q per episode of `results` (training.read_results's) to `path`."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    figure, (top, bottom) = plt.subplots(2, 1, figsize=(7.0, 6.0), sharex=True)
    episodes = results['episode']
    top.plot(episodes, results['score'], color='#c0392b', linewidth=0.8)
    top.set_ylabel('total reward')
    top.set_title(title or 'Total reward')
    bottom.plot(episodes, results['max_q'], color='#27ae60', linewidth=0.8)
    bottom.set_ylabel('average max Q')
    bottom.set_xlabel('episode')
    for axes in (top, bottom):
        axes.grid(True, alpha=0.4)
    figure.tight_layout()
    figure.savefig(path, dpi=90)
    plt.close(figure)


def _application(life):
    from PyQt5.QtCore import QTimer
    from PyQt5.QtWidgets import QApplication
    application = QApplication(sys.argv[:1])
    timer = QTimer()
    timer.timeout.connect(lambda: life.stopping and application.quit())
    timer.start(WINDOW_POLL_MS)
    return application, timer


def result_graph():
    """The node result_graph: a window of two plots, redrawn every 0.2 s."""
    import pyqtgraph
    import rospy
    from std_msgs.msg import Float32MultiArray

    from tb3_common.ros import lifecycle

    life = lifecycle.init_node('result_graph')
    application, timer = _application(life)
    episodes, scores, values = [], [], []

    def on_result(message):
        episodes.append(len(episodes) + 1)
        scores.append(message.data[0])
        values.append(message.data[1])
    rospy.Subscriber('result', Float32MultiArray, life.callback(on_result), queue_size=100)
    window = pyqtgraph.GraphicsLayoutWidget(title='Result')
    window.resize(600, 650)
    rewards = window.addPlot(title='Total reward')
    window.nextRow()
    q_values = window.addPlot(title='Average max Q-value')
    for plot in (rewards, q_values):
        plot.showGrid(x=True, y=True)
    reward_curve, q_curve = rewards.plot(pen=(255, 0, 0)), q_values.plot(pen=(0, 255, 0))

    def redraw():
        count = min(len(episodes), len(scores), len(values))
        reward_curve.setData(episodes[:count], scores[:count])
        q_curve.setData(episodes[:count], values[:count])
    redrawing = pyqtgraph.QtCore.QTimer()
    redrawing.timeout.connect(redraw)
    redrawing.start(200)
    window.show()
    application.exec_()
    finish_now(life)


def action_graph():
    """The node action_graph: the action taken, the total reward and the reward, per step."""
    import rospy
    from PyQt5.QtCore import QObject, Qt, pyqtSignal
    from PyQt5.QtWidgets import QGridLayout, QLabel, QLineEdit, QProgressBar, QWidget
    from std_msgs.msg import Float32MultiArray

    from tb3_common.ros import lifecycle

    life = lifecycle.init_node('action_graph')
    application, timer = _application(life)

    class Relay(QObject):  # rospy's thread -> Qt's: a signal
        changed = pyqtSignal(int, str, str)
    relay = Relay()
    form = QWidget()
    form.setWindowTitle('Action State')
    layout = QGridLayout(form)
    bars = []
    for index in range(5):
        bar = QProgressBar()
        bar.setOrientation(Qt.Vertical)
        bar.setRange(0, 100)
        bar.setFormat(' ')
        layout.addWidget(bar, 0, 4 + index, 4, 1)
        bars.append(bar)
    for text, column in (('Left', 4), ('Front', 6), ('Right', 8)):
        layout.addWidget(QLabel(text), 4, column)
    total, reward = QLineEdit(), QLineEdit()
    for row, (text, field) in enumerate((('Total reward', total), ('Reward', reward))):
        field.setDisabled(True)
        field.setFixedWidth(100)
        layout.addWidget(QLabel(text), 2 * row, 0)
        layout.addWidget(field, 2 * row + 1, 0)

    def show(action, score, step_reward):
        for index, bar in enumerate(bars):
            bar.setValue(100 if index == action else 0)
        total.setText(score)
        reward.setText(step_reward)
    relay.changed.connect(show)
    rospy.Subscriber('get_action', Float32MultiArray, life.callback(
        lambda message: relay.changed.emit(int(message.data[0]), str(round(message.data[-2], 2)),
                                           str(round(message.data[-1], 2)))), queue_size=10)
    form.show()
    application.exec_()
    finish_now(life)
