robot gripper_arm {
    chain H1 - L4(port=45deg) - L1
    payload 1e999 kg   # expect: error[not-finite] payload mass must be a finite number
}
