#!/usr/bin/env python3
"""Time to first render of results pages and episode viewers in headless Chromium:
loads each page RUNS times from file:// and prints the median of the first contentful paint and
of the moment the page's script has built it (body[data-ready]), with the page's size without media.

    /usr/bin/python3 bench/pages_bench.py PAGE.html [PAGE.html ...] [--runs 5]
"""
import argparse
import os
import statistics
import sys

from selenium import webdriver
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.support.ui import WebDriverWait


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("pages", nargs="+")
    ap.add_argument("--runs", type=int, default=5)
    args = ap.parse_args()
    options = webdriver.ChromeOptions()
    options.binary_location = "/usr/bin/chromium"
    for arg in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--window-size=1600,1000"):
        options.add_argument(arg)
    driver = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=options)
    try:
        for page in args.pages:
            paint, ready = [], []
            for _ in range(args.runs):
                driver.get("about:blank")
                driver.get("file://" + os.path.abspath(page))
                WebDriverWait(driver, 60).until(lambda d: d.execute_script("return document.body.dataset.ready === 'true'"))
                WebDriverWait(driver, 10).until(lambda d: d.execute_script(
                    "return performance.getEntriesByName('first-contentful-paint').length > 0"))
                paint.append(driver.execute_script("return performance.getEntriesByName('first-contentful-paint')[0].startTime"))
                ready.append(driver.execute_script("return document.body.dataset.readyAt ? Number(document.body.dataset.readyAt) : NaN"))
            size = os.path.getsize(page)
            print(f"{page}: {size / 1e3:.1f} kB without media; first contentful paint median {statistics.median(paint):.0f} ms"
                  f" (of {args.runs}); table built at median {statistics.median(ready):.0f} ms")
    finally:
        driver.quit()
    return 0


if __name__ == "__main__":
    sys.exit(main())
