# A one-joint wrist: the count of joints is singular.
robot wrist {
    allow first-variant
    chain L1
    pose up (10, 20) deg   # expect: error[pose-arity] pose 'up' has 2 values; robot 'wrist' has 1 joint
}
