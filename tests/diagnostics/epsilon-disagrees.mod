# corpus-analyses: torque
# Four light modules break the paper's epsilon rule (allowed here), yet the torque check finds
# every joint within its nominal torque: a note says the two disagree.
robot tabletop {   # expect: note[epsilon-disagrees] robot 'tabletop' has more modules of one kind than ε allows, yet every joint stays within its nominal torque (tightest: joint_2, 4.39 of 12 N·m)
    chain H1 - H4(pivot=-90deg) - L1 - L1 - L1 - L1
    allow epsilon-exceeded
}
