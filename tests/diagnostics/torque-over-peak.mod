# corpus-analyses: torque
# 1.5 kg at the end of a 500 mm light link: joint 3 (a KA-58, peak 6.8 N·m) cannot hold it, and
# joint 2 needs more than its nominal torque.
robot gripper_arm {
    chain H1 - H3(pivot=-90deg)   # expect: warning[torque-over-nominal] joint_2 (H3) must hold 16 N·m against gravity at q = (0, 90, 0, 0) deg, above its nominal 12 N·m (peak 30.5 N·m)
        - L3(link=500mm)   # expect: error[torque-over-peak] joint_3 (L3) must hold 10.2 N·m against gravity at q = (0, -134, 44, 0) deg, above its peak 6.8 N·m
        - L1
    payload 1.5 kg
}
