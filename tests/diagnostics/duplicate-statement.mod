robot gripper_arm {
    chain H1 - L4(port=45deg) - L1
    payload 0.5 kg
    payload 300 g at (0, 0, 0.05) m   # expect: error[duplicate-statement] 'payload' is given twice in robot 'gripper_arm'
}
