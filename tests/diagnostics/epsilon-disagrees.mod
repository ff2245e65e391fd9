# corpus-analyses: torque
# Four light modules break the paper's epsilon rule (allowed here), yet the torque check finds
# every joint within its nominal torque: a note says the two disagree.
robot tabletop {   # expect: note[epsilon-disagrees]
    chain H1 - H4(pivot=-90deg) - L1 - L1 - L1 - L1
    allow epsilon-exceeded
}
