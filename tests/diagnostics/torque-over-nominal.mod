# corpus-analyses: torque
# Half-metre links on the shoulder: joint 2 holds 15.5 N·m at worst, above the KA-75+'s nominal
# 12 N·m (within its 30.5 N·m peak): a warning from the torque check (`modc check`, compile).
robot longreach {
    chain H1
        - H4(pivot=-90deg, link=500mm)   # expect: warning[torque-over-nominal] joint_2 (H4) must hold 15.5 N·m against gravity at q = (0, 90, 0, 0) deg, above its nominal 12 N·m (peak 30.5 N·m)
        - H3(link=500mm)
        - L1
    payload 0.5 kg
}
