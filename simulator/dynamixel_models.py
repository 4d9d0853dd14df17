"""Factory ("Initial Value") control tables of the X-series models the arm driver accepts,
as the ROBOTIS e-manual publishes them — the emulator's only source for them.

Each entry cites the page it was read from: repository ``ROBOTIS-GIT/emanual``, the path, and
the commit of the revision read. Nothing here is derived from the driver.

Per-model differences that matter (all from the pages cited below):

* **Shutdown (63)**: 52 (0x34: overheating, electrical shock, overload) on every model except
  the XL330-M288: 53 (0x35), which adds the Input Voltage Error bit — an XL330 drops torque on
  an input-voltage error, the others keep driving (Shutdown include, XL330 row "Input Voltage
  Error (default)").
* **Current Limit (38)**: absent on the XL430-W250 and 2XL430-W250 (no address 38 in their
  tables; address 126 is Present *Load* there, not Present Current); 1 mA units on the XL330
  (0..1,750), about 2.69 mA units on the XM/XH (XM430 0..1,193, XH430-W350 0..648, XM540
  0..2,047).
* **Velocity Limit (44)** differs per model (0.229 rev/min units; XL330 range 0..2,047, others
  0..1,023). "The default value of Velocity Limit has been decreased since Firmware V42"
  (velocity-limit include): older revisions of the pages list larger values (XL430-W250 415,
  XM430-W350 350) in tables that still had an Acceleration Limit (40).
* **Voltage limits (32/34)** and **Temperature Limit (31)** differ per model: the XL330 is a 5 V
  servo (limits 3.5..7.0 V), so the 12 V a bench supply gives an XL430 arm is outside them.
* Model-only registers: Startup Configuration (60) on the XL430-W250, XM430-W210, XH430-W350,
  XM540-W270 and XL330-M288 revisions read (not on the 2XL430-W250 and XM430-W350 revisions
  read); PWM Slope (62) on the XL330 only; External Port Mode 1..3 (56..58) on the XM540 only.

The same on every model read: Return Delay Time 250 (x 2 us = 500 us), Moving Threshold 10,
PWM Limit 885, Min/Max Position Limit 0/4,095, Baud Rate 1 (57,600 bps), Operating Mode 3,
Secondary ID 255, Protocol Type 2, Status Return Level (RAM, 68) 2.
"""

from __future__ import annotations

from dataclasses import dataclass, field

EMANUAL_REPO = "ROBOTIS-GIT/emanual"
#: Specifications data (Input Voltage, "Recommended") for every X-series page.
SPEC_DATA = ("_data/dxl_x_info.yml", "00280385680aba081862d0854c95de523c6391e6")


@dataclass(frozen=True)
class FactoryTable:
    """Initial values of one model's control table (EEPROM, plus Status Return Level)."""

    model_number: int
    name: str
    source_path: str
    source_commit: str
    return_delay_time: int  # 2 us units
    temperature_limit: int  # deg C
    max_voltage_limit: int  # 0.1 V
    min_voltage_limit: int  # 0.1 V
    pwm_limit: int  # 0.113 %
    current_limit: int | None  # None: the model has no Current Limit (38)
    velocity_limit: int  # 0.229 rev/min
    max_position_limit: int
    min_position_limit: int
    shutdown: int
    moving_threshold: int  # 0.229 rev/min
    status_return_level: int
    #: Specifications, Input Voltage "Recommended" (0.1 V): the supply an emulated servo sees
    recommended_supply_decivolts: int
    baud_rate: int = 1
    operating_mode: int = 3
    drive_mode: int = 0
    secondary_id: int = 255
    protocol_type: int = 2
    homing_offset: int = 0
    #: Other EEPROM registers only some models have: {address: (size, initial value)}
    extra: dict[int, tuple[int, int]] = field(default_factory=dict)

    @property
    def source(self) -> str:
        return f"{EMANUAL_REPO} {self.source_path} @ {self.source_commit}"


def _page(model: str) -> str:
    return f"docs/en/dxl/x/{model}.md"


#: Model Number -> factory table, one per model in ``dynamixel_table.MODEL_NAMES``.
FACTORY_TABLES: dict[int, FactoryTable] = {
    t.model_number: t
    for t in (
        FactoryTable(
            1060, "XL430-W250", _page("xl430-w250"), "00a4b781d5a52e9b62599ea084cabc11e33b3b46",
            return_delay_time=250, temperature_limit=72, max_voltage_limit=140,
            min_voltage_limit=60, pwm_limit=885, current_limit=None, velocity_limit=265,
            max_position_limit=4095, min_position_limit=0, shutdown=52, moving_threshold=10,
            status_return_level=2, recommended_supply_decivolts=111,
            extra={60: (1, 0)},  # Startup Configuration
        ),
        FactoryTable(
            1090, "2XL430-W250", _page("2xl430-w250"), "1663e9e2d101cdcf0fcd467a6b660c3bbdf22d1d",
            return_delay_time=250, temperature_limit=72, max_voltage_limit=140,
            min_voltage_limit=60, pwm_limit=885, current_limit=None, velocity_limit=250,
            max_position_limit=4095, min_position_limit=0, shutdown=52, moving_threshold=10,
            status_return_level=2, recommended_supply_decivolts=111,
        ),
        FactoryTable(
            1020, "XM430-W350", _page("xm430-w350"), "08551725617f8cdf053bc7c28c422b9ab10dadd4",
            return_delay_time=250, temperature_limit=80, max_voltage_limit=160,
            min_voltage_limit=95, pwm_limit=885, current_limit=1193, velocity_limit=200,
            max_position_limit=4095, min_position_limit=0, shutdown=52, moving_threshold=10,
            status_return_level=2, recommended_supply_decivolts=120,
        ),
        FactoryTable(
            1030, "XM430-W210", _page("xm430-w210"), "028a13d257d7b1869b6f46af65d482c912b6852f",
            return_delay_time=250, temperature_limit=80, max_voltage_limit=160,
            min_voltage_limit=95, pwm_limit=885, current_limit=1193, velocity_limit=330,
            max_position_limit=4095, min_position_limit=0, shutdown=52, moving_threshold=10,
            status_return_level=2, recommended_supply_decivolts=120,
            extra={60: (1, 0)},
        ),
        FactoryTable(
            1000, "XH430-W350", _page("xh430-w350"), "028a13d257d7b1869b6f46af65d482c912b6852f",
            return_delay_time=250, temperature_limit=80, max_voltage_limit=160,
            min_voltage_limit=95, pwm_limit=885, current_limit=648, velocity_limit=130,
            max_position_limit=4095, min_position_limit=0, shutdown=52, moving_threshold=10,
            status_return_level=2, recommended_supply_decivolts=120,
            extra={60: (1, 0)},
        ),
        FactoryTable(
            1120, "XM540-W270", _page("xm540-w270"), "028a13d257d7b1869b6f46af65d482c912b6852f",
            return_delay_time=250, temperature_limit=80, max_voltage_limit=160,
            min_voltage_limit=95, pwm_limit=885, current_limit=2047, velocity_limit=128,
            max_position_limit=4095, min_position_limit=0, shutdown=52, moving_threshold=10,
            status_return_level=2, recommended_supply_decivolts=120,
            extra={56: (1, 3), 57: (1, 3), 58: (1, 3), 60: (1, 0)},  # External Port Mode 1..3
        ),
        FactoryTable(
            1200, "XL330-M288", _page("xl330-m288"), "028a13d257d7b1869b6f46af65d482c912b6852f",
            return_delay_time=250, temperature_limit=70, max_voltage_limit=70,
            min_voltage_limit=35, pwm_limit=885, current_limit=1750, velocity_limit=445,
            max_position_limit=4095, min_position_limit=0, shutdown=53, moving_threshold=10,
            status_return_level=2, recommended_supply_decivolts=50,
            extra={60: (1, 0), 62: (1, 140)},  # Startup Configuration, PWM Slope
        ),
    )
}  # fmt: skip


def factory_table(model_number: int) -> FactoryTable:
    """The e-manual's factory table of ``model_number`` (KeyError names the known models)."""
    try:
        return FACTORY_TABLES[model_number]
    except KeyError:
        known = ", ".join(f"{n} ({t.name})" for n, t in FACTORY_TABLES.items())
        raise KeyError(
            f"no e-manual factory table for model number {model_number}; known: {known}"
        ) from None
