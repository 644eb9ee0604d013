"""MCAP recording and exact replay, in the rosbag2 layout (metadata.yaml + .mcap).

schema.py   message definitions (ros2msg) and type hashes for the MCAP schemas
writer.py   BagWriter: a rosbag2-compatible bag directory
cdr.py      canonical CDR: messages exactly as long as their data, padding zeroed (every reader)
reader.py   BagReader: messages of a bag directory or a bare .mcap
recorder.py Recorder: what the controller did, sample for sample, from the runner
replay.py   replay(): the recorded commands into a fresh controller, compared (bags of
            mpi-ros record, or of any recorder of the graph: /mpi/commands, /mpi/configuration)
scenario.py scripted runs (the regression fixtures are recorded from them)
playback.py play(): a bag's topics onto the ROS graph with their original timing
"""
