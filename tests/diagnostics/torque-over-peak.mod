# corpus-analyses: torque
# 1.5 kg at the end of a 500 mm light link: joint 3 (a KA-58, peak 6.8 N·m) cannot hold it, and
# joint 2 needs more than its nominal torque.
robot gripper_arm {
    chain H1 - H3(pivot=-90deg)   # expect: warning[torque-over-nominal]
        - L3(link=500mm)   # expect: error[torque-over-peak]
        - L1
    payload 1.5 kg
}
