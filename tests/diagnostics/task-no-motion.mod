# A task visiting one place and straight paths joining a point to itself have nothing to time.
design cell {
    target a at (0.3, 0, 0.2) m
    target b at (0.2, 0.1, 0.3) m
    target c at (0.3, 0, 0.2) m
    task stay { visit a }   # expect: warning[task-no-motion] task 'stay' has no motion: it visits one place
    path loop from a to a straight   # expect: warning[task-no-motion] path 'loop' has no motion: 'a' and 'a' are one point
    path twin from a to c straight   # expect: warning[task-no-motion] path 'twin' has no motion: 'a' and 'c' are one point
    path fine from a to b straight
}
