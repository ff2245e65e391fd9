# expect: warning[empty-file] no robot is defined in this file
# A file that only holds comments defines no robot: a warning, not an error.
# robot farm {
#     chain H1 - L4(port=45deg) - L1
# }
