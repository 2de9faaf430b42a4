"""``wallcli report``: self-contained HTML pages an analyst can hand over.

``analysis`` decodes a clip once into everything its page shows; ``scan`` reads the JSON Lines
of ``wallcli scan``; ``pages`` fills the Jinja2 templates (package data, autoescaped) through
``render``; ``figures`` embeds the figures of ``wallcli.plots`` as data: URIs.
"""
