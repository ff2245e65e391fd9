# corpus-xfail: parser._open_robot counts braces inside "quoted paths", so an unclosed block whose library path holds '}' is reported as a bare syntax-error
robot farm {
    library "libraries/}/mark2.yaml"
    chain H1 - L4(port=45deg) - L1
# expect-line 6: error[unclosed-block]
