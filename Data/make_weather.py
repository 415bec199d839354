#!/usr/bin/python3
"""Writes Data/paris_synthetic.epw: a whole year (2023, 8760 hours) of an EnergyPlus weather
file for Paris (48.85 N, 2.35 E, UTC+1), from a clear-sky model with a deterministic cloud
cover per day, so that the tests and the examples have a weather file of known content.

The sun is at the middle of each hour (NOAA's solar position formulas, good to a few hundredths
of a degree); the irradiances are that instant's, as the hour's mean. Clear sky: Meinel's
direct normal irradiance E0 0.7^(AM^0.678) and Liu and Jordan's diffuse fraction (0.271 -
0.294 tau_b) E0 sin(h). Each day has a cloud cover c in [0, 0.9] from a fixed linear
congruential sequence; clouds take (1 - c) of the beam and add 0.35 c of the clear-sky
beam's horizontal part to the diffuse. Below the horizon every irradiance is 0. The other
fields are plausible but only the date, the hour and the irradiances (fields 1-4 and 14-16) are
read by moving-light-radiosity.

    /usr/bin/python3 Data/make_weather.py [OUTPUT.epw]
"""
import math
import os
import sys

LATITUDE, LONGITUDE, TIME_ZONE, ELEVATION = 48.85, 2.35, 1.0, 35.0
YEAR = 2023
SOLAR_CONSTANT = 1361.0
DAYS = [31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31]


def clouds():
    """A cloud cover per day of the year, from a fixed linear congruential generator."""
    state = 20231
    cover = []
    for _ in range(365):
        state = (1103515245 * state + 12345) % 2 ** 31
        u = state / 2 ** 31
        cover.append(round(0.9 * u * u, 3))  # mostly clear days
    return cover


def sun_elevation(day_of_year, clock_hours):
    """Elevation (degrees) of the sun at a local standard clock time, NOAA's formulas."""
    gamma = 2 * math.pi / 365 * (day_of_year - 1 + (clock_hours - 12) / 24)
    equation_of_time = 229.18 * (0.000075 + 0.001868 * math.cos(gamma) -
                                 0.032077 * math.sin(gamma) - 0.014615 * math.cos(2 * gamma) -
                                 0.040849 * math.sin(2 * gamma))
    declination = (0.006918 - 0.399912 * math.cos(gamma) + 0.070257 * math.sin(gamma) -
                   0.006758 * math.cos(2 * gamma) + 0.000907 * math.sin(2 * gamma) -
                   0.002697 * math.cos(3 * gamma) + 0.00148 * math.sin(3 * gamma))
    solar_minutes = clock_hours * 60 + equation_of_time + 4 * LONGITUDE - 60 * TIME_ZONE
    hour_angle = math.radians(solar_minutes / 4 - 180)
    phi = math.radians(LATITUDE)
    sine = (math.sin(phi) * math.sin(declination) +
            math.cos(phi) * math.cos(declination) * math.cos(hour_angle))
    return math.degrees(math.asin(max(-1.0, min(1.0, sine))))


def hours():
    cover = clouds()
    day_of_year = 0
    for month, days in enumerate(DAYS, start=1):
        for day in range(1, days + 1):
            day_of_year += 1
            c = cover[day_of_year - 1]
            extraterrestrial = SOLAR_CONSTANT * (1 + 0.033 * math.cos(2 * math.pi * day_of_year / 365))
            for hour in range(1, 25):
                elevation = sun_elevation(day_of_year, hour - 0.5)
                sine = math.sin(math.radians(elevation))
                if sine > 0:
                    air_mass = 1 / (sine + 0.50572 * (elevation + 6.07995) ** -1.6364)
                    clear_beam = extraterrestrial * 0.7 ** (air_mass ** 0.678)
                    clear_diffuse = extraterrestrial * sine * max(
                        0.0, 0.271 - 0.294 * clear_beam / extraterrestrial)
                    dni = round(clear_beam * (1 - c))
                    dhi = round(clear_diffuse + 0.35 * c * clear_beam * sine)
                    ghi = round(dni * sine + dhi)
                    ext_horizontal = round(extraterrestrial * sine)
                    ext_normal = round(extraterrestrial)
                else:
                    dni = dhi = ghi = ext_horizontal = ext_normal = 0
                yield month, day, hour, c, ghi, dni, dhi, ext_horizontal, ext_normal, day_of_year


def line(month, day, hour, c, ghi, dni, dhi, ext_horizontal, ext_normal, day_of_year):
    season = math.cos(2 * math.pi * (day_of_year - 200) / 365)
    daily = math.cos(2 * math.pi * (hour - 15) / 24)
    dry_bulb = round(11.5 + 8 * season + 4 * daily * (1 - 0.6 * c), 1)
    dew_point = round(dry_bulb - 6 + 4 * c, 1)
    relative_humidity = round(min(100.0, 100 * math.exp(17.27 * dew_point / (237.7 + dew_point) -
                                                       17.27 * dry_bulb / (237.7 + dry_bulb))))
    sky_cover = round(10 * c)
    fields = [YEAR, month, day, hour, 60, "*9",
              dry_bulb, dew_point, relative_humidity, 101325, ext_horizontal, ext_normal,
              round(280 + 3 * dry_bulb + 4 * sky_cover), ghi, dni, dhi,
              round(110 * ghi), round(95 * dni), round(120 * dhi), 9999,
              230, 3.5, sky_cover, sky_cover, 9999, 77777, 9, 999999999, 15, 0.12, 0, 88, 0.2, 0, 1]
    return ",".join(str(f) for f in fields)


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    output = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "paris_synthetic.epw")
    header = [
        "LOCATION,Paris Synthetic,IDF,FRA,Data/make_weather.py,071560,%.2f,%.2f,%.1f,%.1f" % (
            LATITUDE, LONGITUDE, TIME_ZONE, ELEVATION),
        "DESIGN CONDITIONS,0",
        "TYPICAL/EXTREME PERIODS,0",
        "GROUND TEMPERATURES,0",
        "HOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0",
        "COMMENTS 1,Synthetic year: Meinel clear-sky beam and Liu-Jordan diffuse with a fixed "
        "daily cloud cover; sun at the middle of each hour",
        "COMMENTS 2,Written by Data/make_weather.py of MovingLightRadiosity; not measured data",
        "DATA PERIODS,1,1,Data,Sunday,1/1,12/31",
    ]
    with open(output, "w", newline="\n") as out:
        for text in header:
            out.write(text + "\n")
        for hour in hours():
            out.write(line(*hour) + "\n")


if __name__ == "__main__":
    main()
