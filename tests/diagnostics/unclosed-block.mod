# The closing brace of the robot block was forgotten. The error is reported where the file
# ends: line 7, just past the final newline.
robot cellarm {
    chain H1 - H4(pivot=-90deg) - L3(port=45deg)
    target p1 at (-0.24, -0.23, 0.585) m
# expect-line 7: error[unclosed-block] the file ends inside robot block 'cellarm'
