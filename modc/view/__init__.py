"""`modc view`: a live 3D view of the arm in the browser (docs/analyses.md).

arm.py    one checked robot as shown: shapes, link poses for q, tool0, gravity torques
page.py   the page's state apart from any browser library: file watching, ranking paging, poses, playback
server.py the page drawn with viser, served locally
"""
