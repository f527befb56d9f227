"""The shipped element tables, for the registry to defer importing their modules (mbs_models/elements/
registry.py).  Generated from the modules: do not edit; regenerate with
``python scripts/element_manifest.py --write``.
"""

#: table name -> (module, class name, ORDER, MANY, element: False for a table nested in another)
SHIPPED = {
    'barrel': ('barrel', 'Barrel', 0, False, True),
    'firing': ('firing', 'Firing', 5, False, True),
    'burst': ('firing', 'Burst', 6, False, True),
    'recoil_spring': ('recoil_spring', 'RecoilSpring', 20, False, True),
    'recoil_damper': ('recoil_damper', 'RecoilDamper', 30, False, True),
    'absorber': ('absorber', 'Absorber', 40, True, True),
    'tabulated_spring': ('tabulated_spring', 'TabulatedSpring', 44, True, True),
    'tabulated_damper': ('tabulated_damper', 'TabulatedDamper', 45, True, True),
    'recoil_brake': ('recoil_brake', 'RecoilBrake', 50, False, True),
    'recuperator': ('recuperator', 'Recuperator', 50, False, True),
    'recoil_stop': ('end_stops', 'RecoilStop', 60, False, True),
    'battery_stop': ('end_stops', 'BatteryStop', 61, False, True),
    'cradle': ('cradle', 'Cradle', 70, False, True),
    'carriage': ('carriage', 'Carriage', 95, False, True),
    'band': ('recoil_brake', 'BrakeBand', 100, False, False),
    'contact': ('contact_laws', 'Contact', 100, False, False),
    'pulse': ('firing', 'Pulse', 100, False, False),
    'support': ('carriage', 'Support', 100, False, False),
}
#: every element module of the package when the manifest was written
MODULES = (
    'absorber',
    'barrel',
    'carriage',
    'characteristic',
    'contact_laws',
    'cradle',
    'end_stops',
    'firing',
    'recoil_brake',
    'recoil_damper',
    'recoil_spring',
    'recuperator',
    'tabulated_damper',
    'tabulated_spring',
)
