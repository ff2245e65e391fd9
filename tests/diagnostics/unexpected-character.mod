# '@' is not part of the language: positions are written with `at`.
robot gripper_arm {
    chain H1 - L4(port=45deg) - L1
    payload 0.5 kg @ (0, 0, 0.05) m   # expect: error[unexpected-character] unexpected character '@'
}
