"""Where Gazebo finds what an SDF names: ``model://`` URIs, Fuel URIs, model folders. No ROS.

``model://NAME/rest`` names the folder ``NAME`` in one of the model paths,
searched in this order, as gz-sim and Gazebo classic search them:

1. ``GZ_SIM_RESOURCE_PATH`` (and its older name ``IGN_GAZEBO_RESOURCE_PATH``);
2. ``GAZEBO_MODEL_PATH`` (Gazebo classic's);
3. the folders that packages in ``AMENT_PREFIX_PATH`` export in their
   ``package.xml`` (``<export><gazebo_ros gazebo_model_path="${prefix}/models"/>``,
   ``${prefix}`` being the package's share folder), and each package's own
   ``share/PKG/models`` folder.

A model folder's SDF file is the one its ``model.config`` names for the newest
SDF version it lists (``<sdf version="1.5">model.sdf</sdf>``), else ``model.sdf``.

A Fuel URI (``https://fuel.gazebosim.org/1.0/OWNER/models/NAME[/VERSION]``)
is looked up in the local Fuel cache, ``~/.gz/fuel`` (``GZ_FUEL_CACHE_PATH``
when set), where gz-sim keeps what it downloaded: ``HOST/owner/models/name/VERSION``,
the newest version when the URI gives none.  Nothing is downloaded.
"""

from __future__ import annotations

import os
import pathlib
import urllib.parse
import xml.etree.ElementTree as ElementTree

MODEL_SCHEME = 'model://'
FUEL_SCHEMES = ('https://', 'http://')
RESOURCE_PATH_VARIABLES = ('GZ_SIM_RESOURCE_PATH', 'IGN_GAZEBO_RESOURCE_PATH', 'GAZEBO_MODEL_PATH')
FUEL_CACHE_VARIABLE = 'GZ_FUEL_CACHE_PATH'
DEFAULT_FUEL_CACHE = pathlib.Path('~/.gz/fuel')
MODEL_CONFIG = 'model.config'
DEFAULT_MODEL_FILE = 'model.sdf'
PACKAGE_PREFIX = '${prefix}'
EXPORT_ATTRIBUTES = ('gazebo_model_path', 'gz_sim_resource_path', 'gazebo_media_path')


def model_paths() -> list[pathlib.Path]:
    """Return the folders ``model://`` URIs are looked up in, first first (read at call time)."""
    paths: list[pathlib.Path] = []
    for variable in RESOURCE_PATH_VARIABLES:
        paths += [pathlib.Path(part) for part in os.environ.get(variable, '').split(os.pathsep)
                  if part]
    for prefix in os.environ.get('AMENT_PREFIX_PATH', '').split(os.pathsep):
        share = pathlib.Path(prefix, 'share') if prefix else None
        if share is None or not share.is_dir():
            continue
        for package in sorted(share.iterdir()):
            paths += _exported_paths(package)
    return list(dict.fromkeys(paths))


def _exported_paths(package: pathlib.Path) -> list[pathlib.Path]:
    found = []
    manifest = package / 'package.xml'
    if manifest.is_file():
        try:
            root = ElementTree.parse(manifest).getroot()
        except (ElementTree.ParseError, OSError):
            root = None
        for export in [] if root is None else root.iter('export'):
            for element in export:
                for attribute in EXPORT_ATTRIBUTES:
                    value = element.get(attribute)
                    if value:
                        found += [pathlib.Path(part.replace(PACKAGE_PREFIX, str(package)))
                                  for part in value.split(os.pathsep) if part]
    models = package / 'models'
    if models.is_dir():
        found.append(models)
    return found


def split_model_uri(uri: str) -> tuple[str, str]:
    """Return ``(model name, rest)`` of ``model://name/rest``."""
    name, _, rest = uri[len(MODEL_SCHEME):].partition('/')
    return name, rest


def find_model_folder(name: str) -> pathlib.Path | None:
    """Return the folder of model ``name`` in the model paths, or None."""
    for path in model_paths():
        candidate = path / name
        if candidate.is_dir():
            return candidate
    return None


def resolve_model_uri(uri: str) -> pathlib.Path | None:
    """Return the file or folder ``model://name/rest`` names, or None if no model path has it."""
    name, rest = split_model_uri(uri)
    folder = find_model_folder(name) if name else None
    if folder is None:
        return None
    return folder / urllib.parse.unquote(rest) if rest else folder


def model_sdf_file(folder: pathlib.Path) -> pathlib.Path:
    """Return the SDF file of a model folder: the newest that model.config lists, else model.sdf."""
    config = folder / MODEL_CONFIG
    if config.is_file():
        try:
            root = ElementTree.parse(config).getroot()
        except ElementTree.ParseError:
            root = None
        if root is not None:
            listed = [(_version_key(element.get('version', '')), (element.text or '').strip())
                      for element in root.findall('sdf') if (element.text or '').strip()]
            if listed:
                return folder / max(listed)[1]
    return folder / DEFAULT_MODEL_FILE


def _version_key(text: str) -> tuple[int, ...]:
    try:
        return tuple(int(part) for part in text.split('.'))
    except ValueError:
        return (0,)


def is_fuel_uri(uri: str) -> bool:
    """Whether ``uri`` names a model on a Fuel server (``https://fuel.../models/...``)."""
    return uri.startswith(FUEL_SCHEMES) and '/models/' in uri


def fuel_model_name(uri: str) -> str:
    """Return the model name of a Fuel URI, lower case (``Ground Plane`` -> ``ground plane``)."""
    parts = [urllib.parse.unquote(part) for part in urllib.parse.urlparse(uri).path.split('/')
             if part]
    index = parts.index('models') if 'models' in parts else len(parts)
    return parts[index + 1].lower() if index + 1 < len(parts) else ''


def fuel_cache_folder(uri: str) -> pathlib.Path:
    """Return the folder of the local Fuel cache where the model ``uri`` names would be.

    The version folder when the URI gives one, else the model's folder (whose
    newest version :func:`resolve_fuel_uri` takes).
    """
    parsed = urllib.parse.urlparse(uri)
    parts = [urllib.parse.unquote(part) for part in parsed.path.split('/') if part]
    index = parts.index('models')
    owner = parts[index - 1] if index >= 1 else ''
    name = parts[index + 1] if index + 1 < len(parts) else ''
    cache = pathlib.Path(os.environ.get(FUEL_CACHE_VARIABLE) or DEFAULT_FUEL_CACHE).expanduser()
    folder = cache / parsed.netloc.lower() / owner.lower() / 'models' / name.lower()
    rest = parts[index + 2:]
    if rest and rest[0].isdigit():
        folder = folder / rest[0]
    return folder


def resolve_fuel_uri(uri: str) -> pathlib.Path | None:
    """Return the cached model folder of a Fuel URI (its newest version), or None."""
    folder = fuel_cache_folder(uri)
    if not folder.is_dir():
        return None
    if (folder / MODEL_CONFIG).is_file() or (folder / DEFAULT_MODEL_FILE).is_file():
        return folder
    versions = [child for child in folder.iterdir() if child.is_dir() and child.name.isdigit()]
    return max(versions, key=lambda child: int(child.name)) if versions else None
