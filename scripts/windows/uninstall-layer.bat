@echo off
rem Removes what install-layer.bat registered for the manifest beside this script.
rem   uninstall-layer.bat          all users (HKLM; administrator's prompt)
rem   uninstall-layer.bat /user    this user only (HKCU)
rem The folder itself is left for you to delete.
setlocal
set "ARG=%~1"
set "ROOT=HKLM"
if not defined ARG goto args_ok
set "ROOT=HKCU"
if /i "%ARG%"=="/user" goto args_ok
echo uninstall-layer: unknown argument "%ARG%" (use /user or nothing)
exit /b 2
:args_ok
set "KEY=%ROOT%\SOFTWARE\Khronos\OpenXR\1\ApiLayers\Implicit"
set "MANIFEST=%~dp0XrApiLayer_sdfg_autograsp.json"
reg query "%KEY%" /v "%MANIFEST%" >nul 2>&1
if errorlevel 1 (
  echo uninstall-layer: %MANIFEST% was not registered under %ROOT%
  exit /b 0
)
reg delete "%KEY%" /v "%MANIFEST%" /f >nul
if errorlevel 1 (
  echo uninstall-layer: could not change %ROOT%: run it as administrator, or with /user
  exit /b 1
)
echo uninstall-layer: removed %MANIFEST% from %KEY%
exit /b 0
